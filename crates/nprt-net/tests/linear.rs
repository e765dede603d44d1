//! The linear design: exact under gain and mixture of maps through the frame path, and its
//! basis projection against analytic cases (a constant map, a map made of known spherical
//! harmonics, a half turn about the up axis).

use glam::{Vec2, Vec3};
use nprt_net::cpu::CpuShading;
use nprt_net::encoding::spherical_harmonics::basis;
use nprt_net::{BasisChoice, Design, Init, LightBasis, LightInput, MapNorm, ModelConfig, Shading};
use nprt_net::{Texels, FEATURES};
use nprt_scene::envmap::{uv_to_direction, EnvMap};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

const WIDTH: usize = 128;

/// A map of `width` × `width/2` whose texel at direction d is `f(d)`.
fn map_of(name: &str, width: usize, f: impl Fn(Vec3) -> Vec3) -> EnvMap {
    let h = width / 2;
    let texels = (0..width * h)
        .map(|t| {
            let uv = Vec2::new(
                ((t % width) as f32 + 0.5) / width as f32,
                ((t / width) as f32 + 0.5) / h as f32,
            );
            f(uv_to_direction(uv))
        })
        .collect();
    EnvMap::from_texels(name, width, h, texels).unwrap()
}

/// `n` rows of pixel inputs in [0, 1), seeded.
fn pixel_inputs(n: usize, seed: u64) -> Vec<f32> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..n * FEATURES).map(|_| rng.random::<f32>()).collect()
}

/// A sky with a sun, and a warm lamp low on the other side: maps unlike each other.
fn two_maps() -> (EnvMap, EnvMap) {
    let sun = Vec3::new(0.3, 0.8, -0.5).normalize();
    let sky = map_of("sky", WIDTH, |d| {
        let glow = d.dot(sun).max(0.0).powi(200) * 500.0;
        Vec3::new(0.3, 0.5, 0.9) * (0.5 + 0.5 * d.y.max(0.0)) + Vec3::splat(glow)
    });
    let lamp = Vec3::new(-0.7, -0.1, 0.7).normalize();
    let room = map_of("lamp", WIDTH, |d| {
        Vec3::new(2.0, 1.2, 0.4) * d.dot(lamp).max(0.0).powi(8) * 30.0 + Vec3::splat(0.05)
    });
    (sky, room)
}

/// `a`·first + `b`·second, texel by texel.
fn mixed(first: &EnvMap, a: f32, second: &EnvMap, b: f32) -> EnvMap {
    let texels = (first.texels().iter().zip(second.texels()))
        .map(|(x, y)| *x * a + *y * b)
        .collect();
    EnvMap::from_texels("mix", first.width(), first.height(), texels).unwrap()
}

/// Render under a·E₁ + b·E₂ equals a·render(E₁) + b·render(E₂), to float rounding, for both
/// bases, both normalisations and a rotated map, through the CPU engine's frame path.
#[test]
fn radiance_is_linear_in_the_map() {
    let features = pixel_inputs(700, 3);
    let (sky, lamp) = two_maps();
    for choice in [
        BasisChoice::Sh { band: 3 },
        BasisChoice::Learned { size: 20 },
    ] {
        for norm in MapNorm::ALL {
            let config = ModelConfig {
                encoder_width: 64,
                map_norm: norm,
                basis: Some(choice),
                ..ModelConfig::new(Design::Linear, None)
            };
            let net = config.build(&mut Init::new(7));
            let shading = CpuShading::new(net, [1.3, 0.9, 1.1], 64, norm);
            let px = shading.pixels(&features);
            let render = |m: &EnvMap| shading.radiance(&px, &shading.light_code(m, 35.0));
            let (a, b) = (2.5, 0.4);
            let (r1, r2) = (render(&sky), render(&lamp));
            let together = render(&mixed(&sky, a, &lamp, b));
            let largest = together.iter().fold(0.0f32, |m, v| m.max(v.abs()));
            let worst = (together.iter().zip(r1.iter().zip(&r2)))
                .map(|(t, (x, y))| (t - (a * x + b * y)).abs())
                .fold(0.0f32, f32::max);
            assert!(
                largest > 1e-3,
                "{choice}/{norm}: the network predicts {largest} at most"
            );
            assert!(
                worst < 2e-5 * largest,
                "{choice}/{norm}: off by {worst} of at most {largest}"
            );
        }
    }
}

/// The frame path's code (texels as they are, each channel by its mean) and a map projected by
/// hand agree: a constant map has only the constant function, √(4π) × its mean-divided value
/// (the others to the quadrature's error, texel centres × exact row solid angles).
#[test]
fn a_constant_map_projects_on_the_constant_function_alone() {
    let basis = LightBasis::new(&mut Init::new(0), BasisChoice::Sh { band: 4 }, WIDTH);
    let map = EnvMap::constant(Vec3::new(2.0, 0.5, 7.0)).unwrap();
    let input = LightInput::with_texels(&map, 10.0, WIDTH, MapNorm::Channel, Texels::Linear);
    assert_eq!(input.scale, [2.0, 0.5, 7.0]);
    let code = basis.project(&input.pixels);
    let constant = (4.0 * std::f32::consts::PI).sqrt();
    for (i, v) in code.iter().enumerate() {
        let want = if i < 3 { constant } else { 0.0 };
        assert!(
            (v - want).abs() < 1e-3,
            "coefficient {} channel {}: {v}",
            i / 3,
            i % 3
        );
    }
}

/// A map made of known coefficients of bands 0..=3 projects back onto them (band 4's are 0),
/// and turned half a turn about the up axis (+Y), each coefficient changes sign by its
/// parity: (−1)^l, and once more for m < 0.
#[test]
fn known_coefficients_round_trip_and_turn_with_the_map() {
    let coefficients: Vec<f32> = (0..16).map(|k| ((k * 7 % 11) as f32 - 5.0) / 5.0).collect();
    let map = map_of("harmonics", 512, |d| {
        let mut y = [0.0; 16];
        basis(4, d, &mut y);
        // Kept positive by a constant that only the first coefficient sees.
        let v: f32 = coefficients.iter().zip(&y).map(|(c, y)| c * y).sum::<f32>() + 3.0;
        Vec3::new(v, 2.0 * v, 0.5 * v)
    });
    let sh = LightBasis::new(&mut Init::new(0), BasisChoice::Sh { band: 4 }, WIDTH);
    let mut want: Vec<f32> = coefficients.clone();
    want[0] += 3.0 * (4.0 * std::f32::consts::PI).sqrt();
    want.resize(25, 0.0);
    let project = |turn: f32| {
        let input = LightInput::with_texels(&map, turn, WIDTH, MapNorm::Mean, Texels::Linear);
        let code = sh.project(&input.pixels);
        (code, input.scale)
    };
    for (turn, sign) in [(0.0, false), (180.0, true)] {
        let (code, scale) = project(turn);
        for (k, &w) in want.iter().enumerate() {
            let l = (k as f32).sqrt().floor() as i32;
            let m = k as i32 - l * l - l;
            let flip = if sign {
                (-1f32).powi(l) * if m < 0 { -1.0 } else { 1.0 }
            } else {
                1.0
            };
            for (c, gain) in [1.0, 2.0, 0.5].into_iter().enumerate() {
                let got = code[k * 3 + c] * scale[c];
                let w = w * gain * flip;
                assert!(
                    (got - w).abs() < 2e-2 * gain,
                    "turn {turn}, Y{k} channel {c}: {got}, want {w}"
                );
            }
        }
    }
}
