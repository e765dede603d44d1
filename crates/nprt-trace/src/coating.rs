//! The dielectric coat of Mitsuba 3's `plastic` and `roughplastic`: how much light the interface
//! lets through towards the diffuse base at each angle, and how much of the base's light it
//! reflects back inside. For a smooth coat both come from the Fresnel equations; for a rough
//! one Mitsuba integrates them over the GGX microfacets once per material, and so do we (the
//! same quadrature: Gauss–Legendre over visible normals, a 64-entry table in cos θ).

use glam::Vec3;
use nprt_scene::{fresnel_dielectric, MIN_ALPHA};

use crate::microfacet::GgxDistribution;

/// Table resolution in cos θ (Mitsuba's `MI_ROUGH_TRANSMITTANCE_RES`).
const TABLE_LEN: usize = 64;

#[derive(Clone, Debug)]
pub struct Coating {
    pub eta: f32,
    /// External transmittance at cos θ = k / 63; `None` for a smooth coat (1 − F).
    table: Option<[f32; TABLE_LEN]>,
    /// Fraction of the base's diffuse light the coat reflects back inside.
    pub internal_reflectance: f32,
}

impl Coating {
    /// A coat of relative index `eta` (inside over outside); `rough` uses GGX of `alpha`.
    pub fn new(eta: f32, alpha: f32, rough: bool) -> Self {
        if !rough {
            return Coating {
                eta,
                table: None,
                internal_reflectance: fresnel_diffuse_reflectance(1.0 / eta),
            };
        }
        let ggx = GgxDistribution::new(alpha.max(MIN_ALPHA));
        let cosines = (0..TABLE_LEN).map(|k| (k as f32 / (TABLE_LEN - 1) as f32).max(1e-6));
        let dirs: Vec<Vec3> = cosines
            .map(|mu| Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu))
            .collect();
        let mut table = [0.0; TABLE_LEN];
        for (t, wi) in table.iter_mut().zip(&dirs) {
            *t = interface_albedo(&ggx, *wi, eta, true);
        }
        // Twice the cosine-weighted mean over the table's directions, as Mitsuba computes it.
        let internal = 2.0
            * dirs
                .iter()
                .map(|wi| interface_albedo(&ggx, *wi, 1.0 / eta, false) * wi.z)
                .sum::<f32>()
            / TABLE_LEN as f32;
        Coating {
            eta,
            table: Some(table),
            internal_reflectance: internal,
        }
    }

    /// The rough coat's transmittance table ([`Self::transmittance`] interpolates it).
    pub fn table(&self) -> Option<&[f32; TABLE_LEN]> {
        self.table.as_ref()
    }

    pub fn is_rough(&self) -> bool {
        self.table.is_some()
    }

    /// Transmittance into the coat for light arriving at `cos` (> 0) from outside.
    pub fn transmittance(&self, cos: f32) -> f32 {
        match &self.table {
            None => 1.0 - fresnel_dielectric(cos, self.eta).r,
            Some(t) => {
                let x = cos.clamp(0.0, 1.0) * (TABLE_LEN - 1) as f32;
                let i = (x as usize).min(TABLE_LEN - 2);
                t[i] + (t[i + 1] - t[i]) * (x - i as f32)
            }
        }
    }
}

/// Fraction of light arriving along `wi` that a rough dielectric interface of relative index
/// `eta` transmits (`transmit`) or reflects, single scattering, by Gauss–Legendre quadrature
/// over the visible-normal sample space (32² nodes, 128² when `eta` < 1).
fn interface_albedo(ggx: &GgxDistribution, wi: Vec3, eta: f32, transmit: bool) -> f32 {
    let n = if eta > 1.0 { 32 } else { 128 };
    let (nodes, weights) = gauss_legendre(n);
    let mut sum = 0.0f64;
    for (x, wx) in nodes.iter().zip(&weights) {
        for (y, wy) in nodes.iter().zip(&weights) {
            let u = glam::Vec2::new(0.5 * *x as f32 + 0.5, 0.5 * *y as f32 + 0.5);
            let m = ggx.sample_visible_normal(wi, u);
            let f = fresnel_dielectric(wi.dot(m), eta);
            let value = if transmit {
                let wo = m * (wi.dot(m) * f.eta_ti + f.cos_t) - wi * f.eta_ti;
                if wo.z * wi.z >= 0.0 {
                    0.0
                } else {
                    ggx.g1(wo, m) * (1.0 - f.r)
                }
            } else {
                let wo = 2.0 * wi.dot(m) * m - wi;
                if wo.z <= 0.0 || wi.z <= 0.0 {
                    0.0
                } else {
                    ggx.g1(wo, m) * f.r
                }
            };
            sum += value as f64 * wx * wy * 0.25;
        }
    }
    sum as f32
}

/// Nodes and weights of n-point Gauss–Legendre quadrature on [−1, 1] (Newton's method on the
/// Legendre polynomial from Chebyshev starting points).
fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let (mut nodes, mut weights) = (vec![0.0; n], vec![0.0; n]);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(x) and its derivative by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let step = p1 / dp;
            x -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        nodes[i] = x;
        weights[i] = 2.0 / ((1.0 - x * x) * dp * dp);
    }
    (nodes, weights)
}

/// Hemispherical average of the Fresnel reflectance for light arriving from a medium of
/// relative index `eta` (the fits Mitsuba 3 uses: Egan & Hilgeman 1973 below 1, d'Eon &
/// Irving 2011 above).
fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    let inv = 1.0 / eta;
    if eta < 1.0 {
        0.0636 * inv + eta * (eta * -1.4399 + 0.7099) + 0.6681
    } else {
        [0.919317, -3.4793, 6.75335, -7.80989, 4.98554, -1.36881]
            .iter()
            .rev()
            .fold(0.0, |acc, c| acc * inv + c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadrature_is_exact_for_polynomials() {
        let (x, w) = gauss_legendre(8);
        let integral =
            |f: &dyn Fn(f64) -> f64| x.iter().zip(&w).map(|(x, w)| f(*x) * w).sum::<f64>();
        assert!((integral(&|_| 1.0) - 2.0).abs() < 1e-12);
        assert!((integral(&|x| x.powi(14)) - 2.0 / 15.0).abs() < 1e-12);
    }

    /// A nearly smooth rough coat transmits what the Fresnel equations say, and its internal
    /// reflectance is the diffuse Fresnel reflectance.
    #[test]
    fn a_nearly_smooth_coat_matches_fresnel() {
        let (rough, smooth) = (
            Coating::new(1.5, 0.002, true),
            Coating::new(1.5, 0.0, false),
        );
        for c in [0.2, 0.5, 0.9, 1.0] {
            assert!(
                (rough.transmittance(c) - smooth.transmittance(c)).abs() < 5e-3,
                "cos {c}: {} vs {}",
                rough.transmittance(c),
                smooth.transmittance(c)
            );
        }
        assert!((smooth.transmittance(1.0) - 0.96).abs() < 1e-6);
        // F_dr(1/1.5) ≈ 0.596 (internal reflection of a diffuse base under glass).
        assert!((smooth.internal_reflectance - 0.596).abs() < 0.01);
        assert!((rough.internal_reflectance - smooth.internal_reflectance).abs() < 0.02);
    }
}
