//! The reflecting lobes: a Lambertian base plus GGX, with the model's F = 1, a conductor's
//! Fresnel term, or a plastic's dielectric coat over its diffuse base ([`Coating`]).

use glam::{Vec2, Vec3};
use nprt_scene::{fresnel_conductor, fresnel_dielectric, Scattering};
use std::f32::consts::PI;

use super::{Bsdf, BsdfSample};
use crate::coating::Coating;

impl<'a> Bsdf<'a> {
    /// Probability of the specular lobe for light leaving along `wo`: fixed for the model and
    /// conductors; for a plastic, weighted by how much the coat reflects at this angle.
    pub(super) fn specular_probability(&self, wo: Vec3) -> f32 {
        let Some(coat) = self.coating else {
            return self.p_spec;
        };
        let reflected = 1.0 - coat.transmittance(wo.z);
        let (s, d) = (
            reflected * self.p_spec,
            (1.0 - reflected) * (1.0 - self.p_spec),
        );
        if s + d > 0.0 {
            s / (s + d)
        } else {
            0.0
        }
    }

    /// The surface's own f·cos, before the mask's opacity (smooth lobes only).
    pub(super) fn eval_surface(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 || self.is_glass() {
            return Vec3::ZERO;
        }
        let (diffuse, fresnel) = match (self.scattering, self.coating) {
            (Scattering::Plastic { eta, nonlinear, .. }, Some(coat)) => {
                let internal = if nonlinear {
                    self.kd * coat.internal_reflectance
                } else {
                    Vec3::splat(coat.internal_reflectance)
                };
                let base = self.kd / (Vec3::ONE - internal);
                let through = coat.transmittance(wo.z) * coat.transmittance(wi.z) / (eta * eta);
                let m = (wo + wi).normalize();
                let specular = if coat.is_rough() {
                    fresnel_dielectric(wo.dot(m), eta).r
                } else {
                    0.0
                };
                (base * through, Vec3::splat(specular))
            }
            (Scattering::Conductor { eta, k }, _) => {
                let m = (wo + wi).normalize();
                (self.kd, fresnel_conductor(wo.dot(m), eta, k))
            }
            _ => (self.kd, Vec3::ONE),
        };
        let mut f = diffuse * (wi.z / PI);
        if self.p_spec > 0.0 && fresnel != Vec3::ZERO {
            let m = (wo + wi).normalize();
            let g = self.ggx.g1(wo, m) * self.ggx.g1(wi, m);
            f += self.ks * fresnel * (self.ggx.d(m) * g / (4.0 * wo.z));
        }
        f
    }

    /// Density of `sample` for the smooth lobes, before the mask's opacity.
    pub(super) fn pdf_surface(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 || self.is_glass() {
            return 0.0;
        }
        let p_spec = self.specular_probability(wo);
        let mut pdf = (1.0 - p_spec) * wi.z / PI;
        if p_spec > 0.0 && self.coating.is_none_or(Coating::is_rough) {
            let m = (wo + wi).normalize();
            // Visible-normal density G1(ωo)·D(m)·(ωo·m)/cos θo, times the reflection Jacobian.
            pdf += p_spec * self.ggx.g1(wo, m) * self.ggx.d(m) / (4.0 * wo.z);
        }
        pdf
    }

    pub(super) fn sample_reflection(&self, wo: Vec3, u: Vec2, u_lobe: f32) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let p_spec = self.specular_probability(wo);
        let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
        let wi = if u_lobe >= p_spec {
            let r = u.x.sqrt();
            let phi = 2.0 * PI * u.y;
            Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u.x).max(0.0).sqrt())
        } else if let (Some(coat), Scattering::Plastic { eta, .. }) =
            (self.coating, self.scattering)
        {
            if !coat.is_rough() {
                // A smooth coat's delta reflection.
                let weight = self.ks * (fresnel_dielectric(wo.z, eta).r / p_spec);
                return Some(BsdfSample {
                    wi: mirror,
                    weight,
                    pdf: p_spec,
                    delta: true,
                    eta: 1.0,
                });
            }
            let m = self.ggx.sample_visible_normal(wo, u);
            2.0 * wo.dot(m) * m - wo
        } else {
            let m = self.ggx.sample_visible_normal(wo, u);
            2.0 * wo.dot(m) * m - wo
        };
        let pdf = self.pdf_surface(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: self.eval_surface(wo, wi) / pdf,
            pdf,
            delta: false,
            eta: 1.0,
        })
    }
}
