//! Smooth glass: Mitsuba 3's `dielectric` and `thindielectric`, delta reflection and
//! transmission.

use glam::Vec3;
use nprt_scene::{fresnel_dielectric, Scattering};

use super::{Bsdf, BsdfSample};

impl<'a> Bsdf<'a> {
    pub(super) fn is_glass(&self) -> bool {
        matches!(self.scattering, Scattering::Dielectric { .. })
    }

    /// Mitsuba 3's `dielectric` and `thindielectric`: reflection with the probability of the
    /// Fresnel reflectance, weight ks; otherwise transmission with weight kt (times the
    /// radiance compression 1/η² across a refracting interface).
    pub(super) fn sample_glass(
        &self,
        wo: Vec3,
        u_lobe: f32,
        eta: f32,
        thin: bool,
    ) -> Option<BsdfSample> {
        let reflect = Vec3::new(-wo.x, -wo.y, wo.z);
        let (r, wt, weight_t, eta_t) = if thin {
            let r = fresnel_dielectric(wo.z.abs(), eta).r;
            (r * 2.0 / (1.0 + r), -wo, self.kt, 1.0)
        } else {
            let f = fresnel_dielectric(wo.z, eta);
            let wt = Vec3::new(-f.eta_ti * wo.x, -f.eta_ti * wo.y, f.cos_t);
            (f.r, wt, self.kt * (f.eta_ti * f.eta_ti), f.eta_it)
        };
        let (wi, weight, pdf, eta) = if u_lobe <= r {
            (reflect, self.ks, r, 1.0)
        } else {
            (wt, weight_t, 1.0 - r, eta_t)
        };
        (pdf > 0.0 && weight != Vec3::ZERO).then_some(BsdfSample {
            wi,
            weight,
            pdf,
            delta: true,
            eta,
        })
    }
}
