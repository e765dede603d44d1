//! Helpers shared by the network tests: the variants every test covers, batches, and the
//! finite-difference check of a gradient against the f64 reference forward pass.

pub mod reference;

use glam::Vec3;
use nprt_net::cpu::UnetBatch;
use nprt_net::network::radiance_cache::CacheQuery;
use nprt_net::{Activation, Batch, Design, Loss, ModelConfig, NprtNet};
use nprt_net::{Parameters, PositionEncoding, FEATURES};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use reference::Reference;

/// Every design with the paper's inputs and each of its activations, then with a hash grid and
/// its own activation; the designs on a basis also with a learned one.
pub fn variants() -> Vec<ModelConfig> {
    let mut all = Vec::new();
    for design in Design::ALL {
        if design.reads_basis() {
            all.push(ModelConfig {
                basis: Some(nprt_net::BasisChoice::Learned { size: 12 }),
                ..ModelConfig::new(design, None)
            });
        }
        for activation in [Activation::Siren, Activation::Relu] {
            all.push(ModelConfig::new(design, Some(activation)));
        }
        all.push(ModelConfig {
            encoding: PositionEncoding::HashGrid,
            ..ModelConfig::new(design, None)
        });
    }
    all
}

/// Gives every hash grid table values of order one, so that the encoding weighs in the output
/// as in a trained network (an untrained grid holds ±1e-4, next to nothing).
pub fn loud_grids(mut net: NprtNet) -> NprtNet {
    let mut rng = Pcg64Mcg::seed_from_u64(17);
    for grid in net.tracks.iter_mut().filter_map(|t| t.grid.as_mut()) {
        grid.table
            .iter_mut()
            .for_each(|v| *v = rng.random::<f32>() * 2.0 - 1.0);
    }
    net
}

/// A batch of `n` samples that is not a whole number of the CPU engine's blocks, with `views`
/// maps of 64×32 and samples of each map spread through it; seeded.
pub fn random_batch(n: usize, views: usize, seed: u64) -> Batch {
    let w = 64;
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut r = |lo: f32, hi: f32, k: usize| -> Vec<f32> {
        (0..k)
            .map(|_| lo + (hi - lo) * rng.random::<f32>())
            .collect()
    };
    Batch {
        features: r(0.0, 1.0, n * FEATURES),
        radiance: r(0.0, 3.0, n * 3),
        transfer: Vec::new(),
        view: (0..n as i64)
            .map(|i| (i * 7 + i / 5) % views as i64)
            .collect(),
        scale: r(0.5, 1.5, n * 3),
        lights: r(0.0, 2.0, views * 3 * w * w / 2),
        light_width: w,
        picks: None,
    }
}

/// Checks `grads` (the CPU engine's gradient of `loss` on `batch` for `net`) against central
/// differences of the f64 reference's loss (see [`check_against`]; the encoder's tensors only
/// with `encoder`). Returns how many entries were checked.
pub fn check_gradients(
    name: &str,
    net: &NprtNet,
    batch: &Batch,
    loss: Loss,
    grads: &NprtNet,
    encoder: bool,
) -> usize {
    let reference = Reference::new(net);
    let fixed = reference.predict(batch, None);
    let codes = reference.light_codes(batch);
    let first = if encoder {
        0
    } else {
        reference.encoder_tensors()
    };
    check_against(name, reference, grads, first, |r, t| {
        let through = (t >= r.encoder_tensors()).then_some(codes.as_slice());
        r.loss(batch, loss, through, &fixed)
    })
}

/// Checks `grads` against central differences of `value` (the f64 reference's loss, given the
/// tensor nudged): in every tensor from `first` on, two entries, one at random and the largest.
/// Where differences with two steps disagree a ReLU, max or |·| switches within the step and
/// the entry is skipped; such entries must be few. Returns how many entries were checked.
pub fn check_against(
    name: &str,
    mut reference: Reference,
    grads: &NprtNet,
    first: usize,
    value: impl Fn(&Reference, usize) -> f64,
) -> usize {
    let mut engine = Vec::new();
    nprt_net::Parameters::visit(grads, "", &mut |name, _, v| {
        engine.push((name.to_string(), v.to_vec()))
    });
    let mut rng = Pcg64Mcg::seed_from_u64(9);
    let (mut checked, mut kinks) = (0, 0);
    for (t, (tensor, grad)) in engine.iter().enumerate().skip(first) {
        let largest = (0..grad.len())
            .max_by(|&a, &b| grad[a].abs().total_cmp(&grad[b].abs()))
            .unwrap();
        let scale = grad[largest].abs() as f64;
        for index in [rng.random_range(0..grad.len()), largest] {
            let mut at = |delta: f64| {
                let kept = reference.params[t][index];
                reference.params[t][index] += delta;
                let v = value(&reference, t);
                reference.params[t][index] = kept;
                v
            };
            let mut fd = |h: f64| (at(h) - at(-h)) / (2.0 * h);
            let (coarse, fine) = (fd(1e-6), fd(5e-7));
            let close =
                |a: f64, b: f64, abs: f64| (a - b).abs() <= abs + 1e-4 * a.abs().max(b.abs());
            if !close(coarse, fine, 1e-7) {
                kinks += 1;
                continue;
            }
            // The engine computes in f32: its error grows with the tensor's gradients.
            let ours = grad[index] as f64;
            assert!(
                close(fine, ours, 1e-7 + 1e-5 * scale),
                "{name} {tensor} [{index}]: engine {ours:e}, finite difference {fine:e} (largest {scale:e})"
            );
            checked += 1;
        }
    }
    assert!(
        checked >= 4 && kinks * 5 <= checked,
        "{name}: {checked} entries checked, {kinks} skipped at a kink"
    );
    checked
}

/// `views` random U-Net views of h × w (features in [0, 1), radiance in [0, 2), every seventh
/// pixel background) under random 64-wide maps.
pub fn unet_batch(views: usize, (h, w): (usize, usize), seed: u64) -> UnetBatch {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut r = |n: usize, lo: f32, hi: f32| -> Vec<f32> {
        (0..n)
            .map(|_| lo + (hi - lo) * rng.random::<f32>())
            .collect()
    };
    let mask: Vec<f32> = (0..views * h * w)
        .map(|i| (i % 7 != 0) as u8 as f32)
        .collect();
    UnetBatch {
        features: r(views * FEATURES * h * w, 0.0, 1.0),
        radiance: r(views * 3 * h * w, 0.0, 2.0),
        mask,
        lights: r(views * 3 * 64 * 32, 0.0, 2.0),
        light_width: 64,
        scale: r(views * 3, 0.5, 1.5),
        height: h,
        width: w,
    }
}

/// `n` random cache queries: positions inside the unit ball, random directions and normals, a
/// grey-orange diffuse albedo with a little specular.
pub fn cache_queries(n: usize, seed: u64) -> Vec<CacheQuery> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut unit = || {
        Vec3::new(rng.random(), rng.random(), rng.random())
            .map(|v: f32| v * 2.0 - 1.0)
            .normalize()
    };
    (0..n)
        .map(|_| {
            let p = unit();
            CacheQuery {
                position: (p * 0.9).to_array(),
                dir: unit(),
                normal: unit(),
                roughness: 0.3,
                kd: Vec3::new(0.5, 0.4, 0.3),
                ks: Vec3::splat(0.04),
            }
        })
        .collect()
}

/// Euclidean distance of `a` from `b` over b's norm.
pub fn relative_error(a: &[f32], b: &[f32]) -> f64 {
    assert_eq!(a.len(), b.len());
    let d: f64 = a.iter().zip(b).map(|(x, y)| ((x - y) as f64).powi(2)).sum();
    let n: f64 = b.iter().map(|y| (*y as f64).powi(2)).sum();
    (d / n.max(1e-30)).sqrt()
}

/// Each tensor's name and relative error between two networks of one shape, in their visiting
/// order.
pub fn tensor_errors<N: Parameters>(a: &N, b: &N) -> Vec<(String, f64)> {
    let mut tensors = Vec::new();
    b.visit("", &mut |_, _, v| tensors.push(v.to_vec()));
    let mut errors = Vec::new();
    a.visit("", &mut |name, _, v| {
        let e = relative_error(v, &tensors[errors.len()]);
        errors.push((name.to_string(), e))
    });
    errors
}

/// The largest of [`tensor_errors`].
pub fn worst(errors: &[(String, f64)]) -> f64 {
    errors.iter().fold(0.0f64, |m, (_, e)| m.max(*e))
}

/// What `end` moved every parameter by from `start`, as a network of the same shapes.
pub fn update<N: Parameters + Clone>(end: &N, start: &N) -> N {
    let mut d = end.clone();
    let moved: Vec<f32> = (end.flat().iter().zip(start.flat()))
        .map(|(a, b)| a - b)
        .collect();
    d.set_flat(&moved);
    d
}
