//! DESIGN.md's BSDF in a local shading frame (z = normal): a Lambertian lobe kd/π plus a
//! Fresnel-free GGX lobe ks·D·G1(ωo)·G1(ωi) / (4 cos θo cos θi), with Smith's separable
//! shadowing as Mitsuba 3. The diffuse lobe is cosine-sampled, the specular one by GGX visible
//! normals (Heitz 2018); a lobe is picked by the luminance of its albedo.

use glam::{Vec2, Vec3};
use nprt_scene::{luminance, BsdfParams};
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug)]
pub struct Bsdf {
    pub kd: Vec3,
    pub ks: Vec3,
    pub alpha: f32,
    /// Probability of sampling the specular lobe.
    p_spec: f32,
}

/// A sampled direction: ωi, f·cos θi / pdf, and the pdf.
pub struct BsdfSample {
    pub wi: Vec3,
    pub weight: Vec3,
    pub pdf: f32,
}

fn ggx_d(alpha: f32, m: Vec3) -> f32 {
    let a2 = alpha * alpha;
    let c2 = m.z * m.z;
    let denom = c2 * (a2 - 1.0) + 1.0;
    a2 / (PI * denom * denom)
}

/// Smith's G1 for GGX, zero when the microfacet is seen from its back.
fn smith_g1(alpha: f32, v: Vec3, m: Vec3) -> f32 {
    if v.dot(m) * v.z <= 0.0 {
        return 0.0;
    }
    let c2 = v.z * v.z;
    let tan2 = ((1.0 - c2) / c2).max(0.0);
    2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

/// Samples a GGX visible normal for a view direction in the upper hemisphere (Heitz 2018).
fn sample_vndf(alpha: f32, wo: Vec3, u: Vec2) -> Vec3 {
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

impl Bsdf {
    pub fn new(p: BsdfParams) -> Self {
        let (ld, ls) = (luminance(p.kd), luminance(p.ks));
        let p_spec = if ld + ls > 0.0 { ls / (ld + ls) } else { 0.0 };
        Bsdf {
            kd: p.kd,
            ks: p.ks,
            alpha: p.alpha,
            p_spec,
        }
    }

    pub fn is_black(&self) -> bool {
        self.kd == Vec3::ZERO && self.ks == Vec3::ZERO
    }

    /// f(ωo, ωi)·cos θi.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let mut f = self.kd * (wi.z / PI);
        if self.p_spec > 0.0 {
            let m = (wo + wi).normalize();
            let g = smith_g1(self.alpha, wo, m) * smith_g1(self.alpha, wi, m);
            f += self.ks * (ggx_d(self.alpha, m) * g / (4.0 * wo.z));
        }
        f
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let mut pdf = (1.0 - self.p_spec) * wi.z / PI;
        if self.p_spec > 0.0 {
            let m = (wo + wi).normalize();
            // Visible-normal density G1(ωo)·D(m)·(ωo·m)/cos θo, times the reflection Jacobian.
            pdf += self.p_spec * smith_g1(self.alpha, wo, m) * ggx_d(self.alpha, m) / (4.0 * wo.z);
        }
        pdf
    }

    pub fn sample(&self, wo: Vec3, u: Vec2, u_lobe: f32) -> Option<BsdfSample> {
        if wo.z <= 0.0 || self.is_black() {
            return None;
        }
        let wi = if u_lobe < self.p_spec {
            let m = sample_vndf(self.alpha, wo, u);
            2.0 * wo.dot(m) * m - wo
        } else {
            let r = u.x.sqrt();
            let phi = 2.0 * PI * u.y;
            Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u.x).max(0.0).sqrt())
        };
        let pdf = self.pdf(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: self.eval(wo, wi) / pdf,
            pdf,
        })
    }
}

/// An orthonormal frame around a unit normal (Duff et al. 2017).
#[derive(Clone, Copy, Debug)]
pub struct Frame3 {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame3 {
    pub fn new(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame3 { s, t, n }
    }
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    fn params(kd: f32, ks: f32, alpha: f32) -> BsdfParams {
        BsdfParams {
            kd: Vec3::splat(kd),
            ks: Vec3::splat(ks),
            alpha,
        }
    }

    /// Albedo ∫ f cos dωi by uniform hemisphere sampling and by importance sampling must agree.
    #[test]
    fn importance_sampling_matches_uniform_integration() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
        for (kd, ks, alpha) in [
            (0.8, 0.0, 0.3),
            (0.0, 1.0, 0.05),
            (0.0, 1.0, 0.5),
            (0.5, 0.5, 0.2),
        ] {
            let b = Bsdf::new(params(kd, ks, alpha));
            let wo = Vec3::new(0.5, 0.1, 0.8).normalize();
            let n = 400_000;
            let (mut uni, mut imp) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let (u1, u2): (f32, f32) = (rng.random(), rng.random());
                let z = u1;
                let r = (1.0 - z * z).sqrt();
                let wi = Vec3::new(r * (2.0 * PI * u2).cos(), r * (2.0 * PI * u2).sin(), z);
                uni += (b.eval(wo, wi).x * 2.0 * PI) as f64;
                if let Some(s) = b.sample(wo, Vec2::new(rng.random(), rng.random()), rng.random()) {
                    imp += s.weight.x as f64;
                    assert!((b.pdf(wo, s.wi) - s.pdf).abs() < 1e-4 * s.pdf.max(1.0));
                }
            }
            let (uni, imp) = (uni / n as f64, imp / n as f64);
            let tol = if alpha < 0.1 { 0.03 } else { 0.01 };
            assert!(
                (uni - imp).abs() < tol * uni.max(0.1),
                "kd {kd} ks {ks} α {alpha}: uniform {uni} vs sampled {imp}"
            );
            if ks == 0.0 {
                assert!((imp - kd as f64).abs() < 0.005, "diffuse albedo {imp}");
            }
        }
    }

    #[test]
    fn pdf_integrates_to_one() {
        let b = Bsdf::new(params(0.3, 0.7, 0.2));
        let wo = Vec3::new(-0.3, 0.4, 0.6).normalize();
        let (nt, np) = (600, 600);
        let mut total = 0.0f64;
        for j in 0..nt {
            let ct = (j as f32 + 0.5) / nt as f32;
            let st = (1.0 - ct * ct).sqrt();
            for i in 0..np {
                let phi = (i as f32 + 0.5) / np as f32 * 2.0 * PI;
                total += (b.pdf(wo, Vec3::new(st * phi.cos(), st * phi.sin(), ct)) * 2.0 * PI)
                    as f64
                    / (nt * np) as f64;
            }
        }
        // Mass missing from the hemisphere is exactly the specular samples reflected below it.
        let n = 200_000;
        let lost = (0..n)
            .filter(|k| {
                let u = Vec2::new(
                    ((*k as f32 + 0.5) * 0.618_034).fract(),
                    (*k as f32 + 0.5) / n as f32,
                );
                b.sample(wo, u, ((*k as f32) * 0.414_213).fract()).is_none()
            })
            .count() as f64
            / n as f64;
        assert!(lost > 0.0 && lost < 0.1);
        assert!(
            (total - (1.0 - lost)).abs() < 0.005,
            "pdf integrates to {total}, sampling loses {lost}"
        );
    }

    #[test]
    fn reciprocal_and_frame_orthonormal() {
        let b = Bsdf::new(params(0.2, 0.9, 0.3));
        let (a, c) = (
            Vec3::new(0.3, 0.2, 0.9).normalize(),
            Vec3::new(-0.6, 0.1, 0.5).normalize(),
        );
        assert!((b.eval(a, c) / c.z - b.eval(c, a) / a.z).length() < 1e-5);
        for n in [Vec3::Z, -Vec3::Z, Vec3::new(0.3, -0.8, 0.1).normalize()] {
            let f = Frame3::new(n);
            assert!(
                f.s.dot(f.t).abs() < 1e-6
                    && f.s.dot(n).abs() < 1e-6
                    && (f.s.cross(f.t) - n).length() < 1e-5
            );
        }
    }
}
