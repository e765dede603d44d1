//! Fresnel reflectance of smooth interfaces, unpolarised, as Mitsuba 3 computes it: between two
//! dielectrics (glass, the coating of plastic) and at a conductor of complex index η + ik. Here
//! because materials report their normal-incidence reflectance to the G-buffer; the tracer uses
//! the same functions at every angle.

use glam::Vec3;

/// Dielectric Fresnel at an interface of relative index `eta` (inside over outside), for
/// `cos_i` measured on the side of the normal (negative: arriving from inside).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DielectricFresnel {
    /// Reflected fraction (1 under total internal reflection).
    pub r: f32,
    /// Cosine of the refracted direction, on the opposite side to `cos_i`.
    pub cos_t: f32,
    /// Relative index across the interface in the direction of travel into it (η or 1/η).
    pub eta_it: f32,
    /// Its reciprocal.
    pub eta_ti: f32,
}

pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> DielectricFresnel {
    let outside = cos_i >= 0.0;
    let (eta_it, eta_ti) = if outside {
        (eta, 1.0 / eta)
    } else {
        (1.0 / eta, eta)
    };
    let cos_t_sqr = 1.0 - (1.0 - cos_i * cos_i) * eta_ti * eta_ti;
    let (ci, ct) = (cos_i.abs(), cos_t_sqr.max(0.0).sqrt());
    let r = if eta == 1.0 {
        0.0
    } else if ci == 0.0 {
        1.0
    } else {
        let a_s = (ci - eta_it * ct) / (ci + eta_it * ct);
        let a_p = (ct - eta_it * ci) / (ct + eta_it * ci);
        0.5 * (a_s * a_s + a_p * a_p)
    };
    DielectricFresnel {
        r,
        cos_t: if outside { -ct } else { ct },
        eta_it,
        eta_ti,
    }
}

/// Conductor Fresnel per channel for `cos_i` in [0, 1] (K. D. Möller, "Optics", 1988, as
/// Mitsuba 3). η = 0, k = 1 is Mitsuba's `material="none"`: reflectance 1 at every angle.
pub fn fresnel_conductor(cos_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
    let c2 = cos_i * cos_i;
    let s2 = 1.0 - c2;
    let s4 = s2 * s2;
    let temp1 = eta * eta - k * k - Vec3::splat(s2);
    let a2pb2 = (temp1 * temp1 + 4.0 * k * k * eta * eta)
        .max(Vec3::ZERO)
        .sqrt();
    let a = (0.5 * (a2pb2 + temp1)).max(Vec3::ZERO).sqrt();
    let term1 = a2pb2 + Vec3::splat(c2);
    let term2 = 2.0 * cos_i * a;
    let r_s = (term1 - term2) / (term1 + term2);
    let term3 = a2pb2 * c2 + Vec3::splat(s4);
    let term4 = term2 * s2;
    let r_p = r_s * (term3 - term4) / (term3 + term4);
    0.5 * (r_s + r_p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_matches_closed_forms() {
        let f = fresnel_dielectric(1.0, 1.5);
        assert!((f.r - 0.04).abs() < 1e-6 && (f.cos_t + 1.0).abs() < 1e-6);
        let (eta, k) = (Vec3::new(0.2, 1.1, 1.65), Vec3::new(3.9, 2.6, 9.2));
        let expect = ((eta - Vec3::ONE) * (eta - Vec3::ONE) + k * k)
            / ((eta + Vec3::ONE) * (eta + Vec3::ONE) + k * k);
        assert!(
            (fresnel_conductor(1.0, eta, k) - expect)
                .abs()
                .max_element()
                < 1e-5
        );
    }

    #[test]
    fn conductor_without_absorption_is_a_dielectric() {
        for c in [0.05, 0.3, 0.7, 1.0] {
            let d = fresnel_dielectric(c, 1.7).r;
            let m = fresnel_conductor(c, Vec3::splat(1.7), Vec3::ZERO);
            assert!(
                (m - Vec3::splat(d)).abs().max_element() < 1e-5,
                "cos {c}: {d} vs {m}"
            );
        }
        assert_eq!(fresnel_conductor(0.4, Vec3::ZERO, Vec3::ONE), Vec3::ONE);
    }

    #[test]
    fn snell_reciprocity_and_total_internal_reflection() {
        let eta = 1.5;
        let f = fresnel_dielectric(0.6, eta);
        let sin_i = (1.0f32 - 0.36).sqrt();
        let sin_t = (1.0 - f.cos_t * f.cos_t).sqrt();
        assert!((sin_i - eta * sin_t).abs() < 1e-6);
        // The same ray leaving the glass reflects the same fraction.
        let back = fresnel_dielectric(f.cos_t, eta);
        assert!((back.r - f.r).abs() < 1e-6 && (back.cos_t - 0.6).abs() < 1e-5);
        // Beyond the critical angle (sin > 1/1.5) light stays inside.
        assert_eq!(fresnel_dielectric(-0.5, eta).r, 1.0);
    }
}
