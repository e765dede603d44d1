//! The BSDF against its own integrals, Fresnel and Snell, and each lobe's sampling.

use super::*;
use crate::coating::Coating;
use crate::shading_frame::Frame3;
use nprt_scene::{fresnel_conductor, fresnel_dielectric};
use rand::{RngExt, SeedableRng};
use std::f32::consts::PI;

fn plain(p: BsdfParams) -> Bsdf<'static> {
    Bsdf::new(p, None)
}

fn params(kd: f32, ks: f32, alpha: f32) -> BsdfParams {
    BsdfParams::new(Vec3::splat(kd), Vec3::splat(ks), alpha)
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
        let b = plain(params(kd, ks, alpha));
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
    let b = plain(params(0.3, 0.7, 0.2));
    let wo = Vec3::new(-0.3, 0.4, 0.6).normalize();
    let (nt, np) = (600, 600);
    let mut total = 0.0f64;
    for j in 0..nt {
        let ct = (j as f32 + 0.5) / nt as f32;
        let st = (1.0 - ct * ct).sqrt();
        for i in 0..np {
            let phi = (i as f32 + 0.5) / np as f32 * 2.0 * PI;
            total += (b.pdf(wo, Vec3::new(st * phi.cos(), st * phi.sin(), ct)) * 2.0 * PI) as f64
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
    let b = plain(params(0.2, 0.9, 0.3));
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

fn with(scattering: Scattering, opacity: f32) -> Bsdf<'static> {
    plain(BsdfParams {
        kt: Vec3::ONE,
        opacity,
        scattering,
        ..params(0.0, 1.0, 1e-3)
    })
}

/// Glass reflects with the Fresnel probability and refracts by Snell's law with the
/// radiance compression 1/η², entering and leaving; a thin pane sums its inter-reflections.
#[test]
fn glass_follows_fresnel_and_snell() {
    let eta = 1.5;
    let glass = with(Scattering::Dielectric { eta, thin: false }, 1.0);
    for wo in [Vec3::new(0.8, 0.0, 0.6), Vec3::new(0.0, -0.6, -0.8)] {
        let f = fresnel_dielectric(wo.z, eta);
        let n = 10_000;
        let reflected = (0..n)
            .filter(|k| {
                let s = glass
                    .sample(wo, Vec2::ZERO, (*k as f32 + 0.5) / n as f32)
                    .unwrap();
                assert!(s.delta && s.pdf > 0.0);
                if s.wi.z * wo.z > 0.0 {
                    assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
                    assert_eq!((s.weight, s.eta), (Vec3::ONE, 1.0));
                    true
                } else {
                    let sin = |v: Vec3| (v.x * v.x + v.y * v.y).sqrt();
                    assert!((sin(wo) - f.eta_it * sin(s.wi)).abs() < 1e-5);
                    assert!((s.weight - Vec3::splat(f.eta_ti * f.eta_ti)).length() < 1e-5);
                    assert_eq!(s.eta, f.eta_it);
                    false
                }
            })
            .count();
        assert!((reflected as f32 / n as f32 - f.r).abs() < 1e-3);
        assert_eq!(glass.eval(wo, -wo), Vec3::ZERO);
        assert!(!glass.is_smooth());
    }
    let thin = with(Scattering::Dielectric { eta, thin: true }, 1.0);
    let wo = Vec3::new(0.6, 0.0, 0.8);
    let r = fresnel_dielectric(0.8, eta).r;
    let through = thin.sample(wo, Vec2::ZERO, 0.999).unwrap();
    assert_eq!((through.wi, through.weight), (-wo, Vec3::ONE));
    assert!((through.pdf - (1.0 - 2.0 * r / (1.0 + r))).abs() < 1e-6);
}

/// A mask lets light through unchanged with probability 1 − opacity and scales the
/// surface's own scattering by the opacity.
#[test]
fn mask_passes_light_with_probability_one_minus_opacity() {
    let opaque = plain(params(0.8, 0.0, 0.5));
    let masked = plain(BsdfParams {
        opacity: 0.3,
        ..params(0.8, 0.0, 0.5)
    });
    let (wo, wi) = (
        Vec3::new(0.3, 0.1, 0.9).normalize(),
        Vec3::new(-0.5, 0.2, 0.7).normalize(),
    );
    assert!((masked.eval(wo, wi) - 0.3 * opaque.eval(wo, wi)).length() < 1e-7);
    assert!((masked.pdf(wo, wi) - 0.3 * opaque.pdf(wo, wi)).abs() < 1e-7);
    let n = 20_000;
    let mut through = 0;
    let mut albedo = 0.0f64;
    for k in 0..n {
        let u = Vec2::new(
            ((k as f32) * 0.618_034).fract(),
            (k as f32 + 0.5) / n as f32,
        );
        let s = masked
            .sample(wo, u, ((k as f32) * 0.414_213 + 0.1).fract())
            .unwrap();
        if s.delta {
            assert_eq!((s.wi, s.weight), (-wo, Vec3::ONE));
            through += 1;
        } else {
            albedo += s.weight.x as f64;
        }
    }
    assert!((through as f64 / n as f64 - 0.7).abs() < 0.01);
    assert!((albedo / (n - through) as f64 - 0.8).abs() < 0.01);
}

/// A conductor's specular lobe is the model's times its Fresnel reflectance at the
/// microfacet; η = 0, k = 1 (Mitsuba's material "none") is the model itself.
#[test]
fn conductor_lobe_carries_its_fresnel_term() {
    let (eta, k) = (Vec3::new(0.2, 0.92, 1.1), Vec3::new(3.9, 2.45, 2.14));
    let model = plain(params(0.0, 1.0, 0.3));
    let copper = plain(BsdfParams {
        scattering: Scattering::Conductor { eta, k },
        ..params(0.0, 1.0, 0.3)
    });
    let none = plain(BsdfParams {
        scattering: Scattering::Conductor {
            eta: Vec3::ZERO,
            k: Vec3::ONE,
        },
        ..params(0.0, 1.0, 0.3)
    });
    for (wo, wi) in [
        (Vec3::Z, Vec3::Z),
        (
            Vec3::new(0.6, 0.0, 0.8),
            Vec3::new(-0.9, 0.1, 0.3).normalize(),
        ),
    ] {
        let m = (wo + wi).normalize();
        let ratio = copper.eval(wo, wi) / model.eval(wo, wi);
        assert!(
            (ratio - fresnel_conductor(wo.dot(m), eta, k))
                .abs()
                .max_element()
                < 1e-5
        );
        assert!((none.eval(wo, wi) - model.eval(wo, wi)).abs().max_element() < 1e-6);
    }
}

/// Plastics as Mitsuba 3: importance sampling reproduces the evaluated lobes (uniform
/// hemisphere integration), a smooth coat's delta reflection carries exactly F(θo)·ks, and
/// no plastic reflects more than it receives.
#[test]
fn plastic_sampling_matches_its_evaluation() {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
    let wo = Vec3::new(0.6, 0.2, 0.5).normalize();
    for rough in [true, false] {
        let alpha = if rough { 0.2 } else { 1e-3 };
        let coat = Coating::new(1.5, alpha, rough);
        let b = Bsdf::new(
            BsdfParams {
                scattering: Scattering::Plastic {
                    eta: 1.5,
                    rough,
                    nonlinear: true,
                    sampling_weight: 0.4,
                },
                ..params(0.6, 1.0, alpha)
            },
            Some(&coat),
        );
        let n = 400_000;
        let (mut uni, mut imp, mut mirror) = (0.0f64, 0.0f64, 0.0f64);
        for _ in 0..n {
            let (u1, u2): (f32, f32) = (rng.random(), rng.random());
            let r = (1.0 - u1 * u1).sqrt();
            let wi = Vec3::new(r * (2.0 * PI * u2).cos(), r * (2.0 * PI * u2).sin(), u1);
            uni += (b.eval(wo, wi).x * 2.0 * PI) as f64;
            if let Some(s) = b.sample(wo, Vec2::new(rng.random(), rng.random()), rng.random()) {
                if s.delta {
                    assert_eq!(s.wi, Vec3::new(-wo.x, -wo.y, wo.z));
                    mirror += s.weight.x as f64;
                } else {
                    imp += s.weight.x as f64;
                    assert!((b.pdf(wo, s.wi) - s.pdf).abs() < 1e-4 * s.pdf.max(1.0));
                }
            }
        }
        let (uni, imp, mirror) = (uni / n as f64, imp / n as f64, mirror / n as f64);
        assert!(
            (uni - imp).abs() < 0.01 * uni,
            "rough {rough}: uniform {uni} vs sampled {imp}"
        );
        let f = fresnel_dielectric(wo.z, 1.5).r as f64;
        if rough {
            assert_eq!(mirror, 0.0);
        } else {
            assert!(
                (mirror - f).abs() < 0.01 * f,
                "delta lobe {mirror} vs F {f}"
            );
        }
        assert!(imp + mirror < 1.0 && imp > 0.3, "albedo {}", imp + mirror);
    }
}

/// A bump-tilted frame, as Mitsuba 3's `bumpmap`: light between the tilted and the
/// unbumped tangent planes is dropped, the rest is Estevez's terminator term times the
/// plain BSDF (1 for no tilt; 2 / (1 + √(1 + α²·tan²θ)) with α² = tan²(tilt) / 8), samples
/// carry the same factor and densities are unchanged where light passes.
#[test]
fn bump_maps_drop_light_between_the_planes_and_shadow_the_rest() {
    let plain = plain(params(0.5, 0.3, 0.2));
    let wo = Vec3::new(0.2, -0.1, 0.9).normalize();
    let flat = plain.with_bump(Some(Vec3::Z));
    let wi = Vec3::new(-0.4, 0.3, 0.6).normalize();
    assert_eq!(flat.eval(wo, wi), plain.eval(wo, wi));
    // Tilted by 30° about y: the unbumped normal leans towards -x in the bumped frame.
    let tilt = 30f32.to_radians();
    let n = Vec3::new(-tilt.sin(), 0.0, tilt.cos());
    let bumped = plain.with_bump(Some(n));
    // Above the bumped plane, below the unbumped one.
    let between = Vec3::new(0.95, 0.0, 0.1).normalize();
    assert!(between.dot(n) < 0.0 && plain.eval(wo, between) != Vec3::ZERO);
    assert_eq!(bumped.eval(wo, between), Vec3::ZERO);
    assert_eq!(bumped.pdf(wo, between), 0.0);
    let cos = wi.dot(n);
    let tan2 = |c: f32| (1.0 - c * c) / (c * c);
    let a2 = tilt.tan().powi(2) / 8.0;
    let factor = 2.0 / (1.0 + (1.0 + a2 * tan2(cos)).sqrt());
    assert!(factor < 1.0 && factor > 0.9);
    assert!((bumped.eval(wo, wi) - plain.eval(wo, wi) * factor).length() < 1e-6);
    assert_eq!(bumped.pdf(wo, wi), plain.pdf(wo, wi));
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(5);
    let mut dropped = 0;
    for _ in 0..2000 {
        match bumped.sample(wo, Vec2::new(rng.random(), rng.random()), rng.random()) {
            Some(s) => {
                let expected = bumped.eval(wo, s.wi) / s.pdf;
                assert!((s.weight - expected).length() < 1e-4 * expected.length().max(1.0));
            }
            None => dropped += 1,
        }
    }
    // Diffuse samples between the planes are dropped: 6.7% of the cosine lobe (the disk's
    // part beyond x = cos 30°·√(1 − y²)), 62.5% of samples diffuse, so about 84 of 2000.
    assert!(dropped > 40 && dropped < 140, "{dropped}");
}
