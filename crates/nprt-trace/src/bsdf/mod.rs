//! DESIGN.md's BSDF in a local shading frame (z = normal): a Lambertian lobe kd/π plus a GGX
//! lobe ks·F·D·G1(ωo)·G1(ωi) / (4 cos θo cos θi), with Smith's separable shadowing as Mitsuba 3
//! and F = 1 (the model) or a conductor's Fresnel reflectance. The diffuse lobe is
//! cosine-sampled, the specular one by GGX visible normals (Heitz 2018); a lobe is picked by
//! the luminance of its albedo. Beyond the model, as Mitsuba 3 evaluates and samples them:
//! plastics (a dielectric coat over a diffuse base, [`Coating`]), smooth glass
//! (`dielectric`, `thindielectric`) and opacity masks (`mask`), the last two with delta lobes,
//! and bump maps (`bumpmap`: the frame is the bumped one, see [`Bsdf::with_bump`]).

use glam::{Vec2, Vec3};
use nprt_scene::{luminance, BsdfParams, Scattering};

use crate::coating::Coating;
use crate::microfacet::GgxDistribution;

mod bump;
mod glass;
mod reflection;
#[cfg(test)]
mod tests;

#[derive(Clone, Copy, Debug)]
pub struct Bsdf<'a> {
    pub kd: Vec3,
    pub ks: Vec3,
    pub alpha: f32,
    kt: Vec3,
    opacity: f32,
    scattering: Scattering,
    /// The plastic's coat (`Scattering::Plastic` only).
    coating: Option<&'a Coating>,
    ggx: GgxDistribution,
    /// Probability of sampling the specular lobe (of the reflecting part) for the model and
    /// conductors; Mitsuba's specular sampling weight for plastics.
    p_spec: f32,
    /// The normal before a bump map tilted the frame, in that frame.
    unbumped: Option<Vec3>,
}

/// A sampled direction: ωi, f·cos θi / pdf, and the pdf (of the discrete choice for a delta
/// lobe, whose sample no other strategy can produce).
pub struct BsdfSample {
    pub wi: Vec3,
    pub weight: Vec3,
    pub pdf: f32,
    pub delta: bool,
    /// Relative index crossed (η for a refraction into glass, 1 otherwise), for Russian roulette.
    pub eta: f32,
}

impl<'a> Bsdf<'a> {
    /// `coating` must be given for plastics (the tracer builds one per material).
    pub fn new(p: BsdfParams, coating: Option<&'a Coating>) -> Self {
        let p_spec = match p.scattering {
            Scattering::Plastic {
                sampling_weight, ..
            } => sampling_weight,
            _ => {
                let (ld, ls) = (luminance(p.kd), luminance(p.ks));
                if ld + ls > 0.0 {
                    ls / (ld + ls)
                } else {
                    0.0
                }
            }
        };
        Bsdf {
            kd: p.kd,
            ks: p.ks,
            alpha: p.alpha,
            kt: p.kt,
            opacity: p.opacity,
            scattering: p.scattering,
            coating: coating.filter(|_| matches!(p.scattering, Scattering::Plastic { .. })),
            ggx: GgxDistribution::new(p.alpha),
            p_spec,
            unbumped: None,
        }
    }

    /// Whether light arriving along `wo` can leave in any direction.
    pub fn scatters(&self, wo: Vec3) -> bool {
        self.opacity < 1.0
            || if self.is_glass() {
                self.ks != Vec3::ZERO || self.kt != Vec3::ZERO
            } else {
                wo.z > 0.0 && (self.kd != Vec3::ZERO || self.ks != Vec3::ZERO)
            }
    }

    /// Whether `eval` can be non-zero: next-event estimation is worth a shadow ray.
    pub fn is_smooth(&self) -> bool {
        !self.is_glass() && self.opacity > 0.0
    }

    /// f(ωo, ωi)·cos θi.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.eval_surface(wo, wi) * (self.opacity * self.bump_factor(wi))
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.bump_factor(wi) == 0.0 {
            return 0.0;
        }
        self.pdf_surface(wo, wi) * self.opacity
    }

    /// Samples ωi; `u_lobe` picks among lobes (pass-through, reflection, refraction) first.
    pub fn sample(&self, wo: Vec3, u: Vec2, u_lobe: f32) -> Option<BsdfSample> {
        if !self.scatters(wo) {
            return None;
        }
        if u_lobe >= self.opacity {
            return Some(BsdfSample {
                wi: -wo,
                weight: Vec3::ONE,
                pdf: 1.0 - self.opacity,
                delta: true,
                eta: 1.0,
            });
        }
        let u_lobe = u_lobe / self.opacity;
        let mut s = match self.scattering {
            Scattering::Dielectric { eta, thin } => self.sample_glass(wo, u_lobe, eta, thin),
            _ => self.sample_reflection(wo, u, u_lobe),
        }?;
        let bump = self.bump_factor(s.wi);
        if bump == 0.0 {
            return None;
        }
        s.weight *= bump;
        s.pdf *= self.opacity;
        Some(s)
    }
}
