//! The GGX (Trowbridge-Reitz) microfacet distribution with Smith's separable shadowing, in a
//! local frame (z = macro-normal), as Mitsuba 3's `microfacet` with `sample_visible`.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug)]
pub struct GgxDistribution {
    /// GGX α (Mitsuba's `alpha`, not the perceptual roughness).
    pub alpha: f32,
}

impl GgxDistribution {
    pub fn new(alpha: f32) -> Self {
        GgxDistribution { alpha }
    }

    /// Density D(m) of micro-normals m.
    pub fn d(&self, m: Vec3) -> f32 {
        let a2 = self.alpha * self.alpha;
        let c2 = m.z * m.z;
        let denom = c2 * (a2 - 1.0) + 1.0;
        a2 / (PI * denom * denom)
    }

    /// Smith's G1 for direction v and micro-normal m, zero when m is seen from its back.
    pub fn g1(&self, v: Vec3, m: Vec3) -> f32 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        let c2 = v.z * v.z;
        let tan2 = ((1.0 - c2) / c2).max(0.0);
        2.0 / (1.0 + (1.0 + self.alpha * self.alpha * tan2).sqrt())
    }

    /// A micro-normal visible from `wo` (upper hemisphere), distributed as
    /// G1(wo, m)·D(m)·max(0, wo·m) / cos θo (Heitz 2018).
    pub fn sample_visible_normal(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let alpha = self.alpha;
        let vh = Vec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
        let len2 = vh.x * vh.x + vh.y * vh.y;
        let t1 = if len2 > 0.0 {
            Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt()
        } else {
            Vec3::X
        };
        let t2 = vh.cross(t1);
        let r = u.x.sqrt();
        let phi = 2.0 * PI * u.y;
        let p1 = r * phi.cos();
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
        let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(1e-6)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ f(m) dm over the hemisphere by a midpoint rule in (cos θ, φ).
    fn integrate(f: impl Fn(Vec3) -> f64) -> f64 {
        let (nt, np) = (2000, 256);
        let mut total = 0.0;
        for j in 0..nt {
            let ct = (j as f32 + 0.5) / nt as f32;
            let st = (1.0 - ct * ct).sqrt();
            for i in 0..np {
                let phi = (i as f32 + 0.5) / np as f32 * 2.0 * PI;
                total += f(Vec3::new(st * phi.cos(), st * phi.sin(), ct));
            }
        }
        total * 2.0 * PI as f64 / (nt * np) as f64
    }

    /// The projected micro-normal area is the macro-surface: ∫ D(m) cos θm dm = 1, and the
    /// visible normals' density integrates to one for any view (Heitz 2014, Eq. 2 and 16).
    #[test]
    fn distributions_are_normalised() {
        for alpha in [0.1, 0.3, 0.8] {
            let g = GgxDistribution::new(alpha);
            let projected = integrate(|m| (g.d(m) * m.z) as f64);
            assert!(
                (projected - 1.0).abs() < 2e-3,
                "α {alpha}: ∫D cos = {projected}"
            );
            let wo = Vec3::new(0.6, -0.2, 0.5).normalize();
            let visible = integrate(|m| (g.g1(wo, m) * g.d(m) * wo.dot(m).max(0.0) / wo.z) as f64);
            assert!((visible - 1.0).abs() < 2e-3, "α {alpha}: ∫D_wo = {visible}");
        }
    }

    #[test]
    fn visible_normals_face_the_viewer() {
        let g = GgxDistribution::new(0.4);
        let wo = Vec3::new(0.8, 0.1, 0.3).normalize();
        for k in 0..1000 {
            let u = Vec2::new(
                ((k as f32 + 0.5) * 0.618_034).fract(),
                (k as f32 + 0.5) / 1000.0,
            );
            let m = g.sample_visible_normal(wo, u);
            assert!(
                (m.length() - 1.0).abs() < 1e-5 && m.z > 0.0 && m.dot(wo) >= -1e-4,
                "{m}"
            );
        }
    }
}
