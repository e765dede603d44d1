//! DESIGN.md's BSDF in a local shading frame (z = normal): a Lambertian lobe kd/π plus a
//! Fresnel-free GGX lobe ks·D·G1(ωo)·G1(ωi) / (4 cos θo cos θi), with Smith's separable
//! shadowing as Mitsuba 3. The diffuse lobe is cosine-sampled, the specular one by GGX visible
//! normals (Heitz 2018); a lobe is picked by the luminance of its albedo.

use glam::{Vec2, Vec3};
use nprt_scene::{luminance, BsdfParams};
use std::f32::consts::PI;

use crate::microfacet::GgxDistribution;

#[derive(Clone, Copy, Debug)]
pub struct Bsdf {
    pub kd: Vec3,
    pub ks: Vec3,
    pub alpha: f32,
    ggx: GgxDistribution,
    /// Probability of sampling the specular lobe.
    p_spec: f32,
}

/// A sampled direction: ωi, f·cos θi / pdf, and the pdf.
pub struct BsdfSample {
    pub wi: Vec3,
    pub weight: Vec3,
    pub pdf: f32,
}

impl Bsdf {
    pub fn new(p: BsdfParams) -> Self {
        let (ld, ls) = (luminance(p.kd), luminance(p.ks));
        let p_spec = if ld + ls > 0.0 { ls / (ld + ls) } else { 0.0 };
        Bsdf {
            kd: p.kd,
            ks: p.ks,
            alpha: p.alpha,
            ggx: GgxDistribution::new(p.alpha),
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
            let g = self.ggx.g1(wo, m) * self.ggx.g1(wi, m);
            f += self.ks * (self.ggx.d(m) * g / (4.0 * wo.z));
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
            pdf += self.p_spec * self.ggx.g1(wo, m) * self.ggx.d(m) / (4.0 * wo.z);
        }
        pdf
    }

    pub fn sample(&self, wo: Vec3, u: Vec2, u_lobe: f32) -> Option<BsdfSample> {
        if wo.z <= 0.0 || self.is_black() {
            return None;
        }
        let wi = if u_lobe < self.p_spec {
            let m = self.ggx.sample_visible_normal(wo, u);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading_frame::Frame3;
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
