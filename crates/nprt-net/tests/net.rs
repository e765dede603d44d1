//! Networks: parameter counts, gradients against finite differences, weight round-trips.

mod common;

use burn::module::{Module, ModuleMapper, Param, ParamId};
use burn::optim::GradientsParams;
use burn::tensor::{DType, Int, Tensor, TensorData};
use common::{
    exact_gradients, gradient_errors, gradient_values, loud_grids, random_batch, variants, Shapes,
};
use nprt_net::model::folder::{load_weights, save_weights};
use nprt_net::FEATURES;
use nprt_net::{log_l1, Loss};
use nprt_net::{Activation, Design, Device, Init, ModelConfig, NprtNet};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

#[test]
fn transport_parameter_counts_are_the_papers() {
    for design in Design::ALL {
        for activation in [Activation::Siren, Activation::Relu] {
            let net = ModelConfig::new(design, Some(activation))
                .build(&mut Init::new(0, &Device::flex()));
            let (ours, paper) = (net.transport_params(), design.paper_params());
            match design {
                Design::Dsep => assert!(
                    (ours as f64 / paper as f64 - 1.0).abs() < 0.02,
                    "dsep: {ours} vs {paper}"
                ),
                _ => assert_eq!(ours, paper, "{design:?} {activation:?}"),
            }
        }
    }
}

/// A tiny batch in the initialiser's precision: features in the ranges the data has,
/// two maps of 64×32, positive reference radiance.
struct Tiny {
    features: Tensor<2>,
    light: Tensor<4>,
    view: Tensor<1, Int>,
    scale: Tensor<2>,
    reference: Tensor<2>,
}

fn tiny_batch(init: &Init, n: usize, seed: u64) -> Tiny {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut r = |lo: f32, hi: f32| lo + (hi - lo) * rng.random::<f32>();
    let features: Vec<f32> = (0..n * FEATURES).map(|_| r(-1.0, 1.0).abs()).collect();
    let light: Vec<f32> = (0..2 * 3 * 32 * 64).map(|_| r(0.0, 2.0)).collect();
    let scale: Vec<f32> = (0..n * 3).map(|_| r(0.5, 1.5)).collect();
    let reference: Vec<f32> = (0..n * 3).map(|_| r(0.0, 3.0)).collect();
    let view: Vec<i64> = (0..n as i64).map(|i| i % 2).collect();
    Tiny {
        features: init.tensor(features, [n, FEATURES]),
        light: init.tensor(light, [2, 3, 32, 64]),
        view: Tensor::from_data(TensorData::new(view, [n]), &init.device),
        scale: init.tensor(scale, [n, 3]),
        reference: init.tensor(reference, [n, 3]),
    }
}

fn loss(net: &NprtNet, b: &Tiny) -> Tensor<1> {
    let pred = net.forward(
        b.features.clone(),
        b.light.clone(),
        b.view.clone(),
        b.scale.clone(),
    );
    log_l1(pred, b.reference.clone())
}

/// Adds `delta` to one element of one parameter.
struct Nudge {
    id: ParamId,
    index: usize,
    delta: f64,
}
impl ModuleMapper for Nudge {
    fn map_float<const D: usize>(&mut self, p: Param<Tensor<D>>) -> Param<Tensor<D>> {
        if p.id != self.id {
            return p;
        }
        let (index, delta) = (self.index, self.delta);
        p.map(|t| {
            let mut data = t.to_data().convert::<f64>();
            data.as_mut_slice::<f64>().unwrap()[index] += delta;
            Tensor::from_data(data, (&t.device(), DType::F64))
        })
    }
}

fn value(t: Tensor<1>) -> f64 {
    t.into_data().convert::<f64>().as_slice::<f64>().unwrap()[0]
}

/// Every parameter tensor of every design (encoder included, hash grid where there is one),
/// two entries each, one at random and the largest (a grid's table is mostly untouched by a
/// tiny batch): the autodiff gradient against a central difference in f64, where differences
/// with two steps agree (entries at a kink are skipped, and must be few).
#[test]
fn gradients_match_finite_differences() {
    let device = Device::flex().autodiff();
    for variant in variants() {
        let name = format!("{}/{:?}", variant.label(), variant.activation);
        let mut init = Init::with_dtype(3, &device, DType::F64);
        let config = ModelConfig {
            encoder_width: 64,
            ..variant
        };
        let net = loud_grids(config.build(&mut init));
        let batch = tiny_batch(&init, 6, 5);
        let grads = GradientsParams::from_grads(loss(&net, &batch).backward(), &net);
        let mut shapes = Shapes(Vec::new());
        net.visit(&mut shapes);
        let mut rng = Pcg64Mcg::seed_from_u64(9);
        let (mut checked, mut kinks) = (0, 0);
        for (id, dims) in shapes.0 {
            let grad = gradient_values(&grads, id, dims.len());
            let largest = (0..grad.len())
                .max_by(|&a, &b| grad[a].abs().total_cmp(&grad[b].abs()))
                .unwrap();
            for index in [rng.random_range(0..grad.len()), largest] {
                let at = |delta| {
                    let nudged = net.clone().map(&mut Nudge { id, index, delta });
                    value(loss(&nudged, &batch).inner())
                };
                let fd = |h: f64| (at(h) - at(-h)) / (2.0 * h);
                let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 + 1e-4 * a.abs().max(b.abs());
                let (coarse, fd) = (fd(1e-6), fd(5e-7));
                if !close(coarse, fd) {
                    // A ReLU, max or |·| switches within the step: no difference quotient
                    // approximates the derivative there.
                    kinks += 1;
                    continue;
                }
                let ad = grad[index];
                assert!(
                    close(fd, ad),
                    "{name} param {id} [{index}] of {dims:?}: autodiff {ad:e}, finite difference {fd:e}"
                );
                checked += 1;
            }
        }
        assert!(
            checked >= 20 && kinks * 10 <= checked,
            "{name}: {checked} entries checked, {kinks} skipped at a kink"
        );
    }
}

#[test]
fn saved_weights_load_into_a_fresh_network_exactly() {
    let device = Device::flex();
    let dir = std::env::temp_dir().join(format!("nprt-net-weights-{}", std::process::id()));
    for design in Design::ALL {
        let config = ModelConfig {
            encoder_width: 64,
            ..ModelConfig::new(design, None)
        };
        let init = Init::new(1, &device);
        let batch = tiny_batch(&init, 16, 2);
        let net = config.build(&mut Init::new(1, &device));
        let path = dir.join(format!("{}.safetensors", design.name()));
        save_weights(&path, &net, design.name()).unwrap();
        let mut other = config.build(&mut Init::new(2, &device));
        let before = value(loss(&other, &batch));
        load_weights(&path, &mut other, design.name()).unwrap();
        assert_eq!(value(loss(&other, &batch)), value(loss(&net, &batch)));
        assert_ne!(
            before,
            value(loss(&net, &batch)),
            "different seeds give different nets"
        );
        // Weights of one design refuse to load into another, naming both.
        let wrong = if design == Design::Dsep {
            Design::Prt
        } else {
            Design::Dsep
        };
        let mut wrong_net = ModelConfig {
            encoder_width: 64,
            ..ModelConfig::new(wrong, None)
        }
        .build(&mut Init::new(1, &device));
        let err = load_weights(&path, &mut wrong_net, wrong.name())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(design.name()) && err.contains(wrong.name()),
            "{err}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn encoder_input_is_mean_normalised_log_of_the_rotated_map() {
    use nprt_net::{LightInput, MapNorm};
    use nprt_scene::envmap::EnvMap;
    // A constant map: after dividing by the mean over channels, log(1 + 0.5), log(2), log(2.5);
    // after dividing each channel by its own mean, log(2) in all three.
    let map = EnvMap::constant(glam::Vec3::new(2.0, 4.0, 6.0)).unwrap();
    for (norm, scale, expect) in [
        (MapNorm::Mean, [4.0; 3], [0.5f32, 1.0, 1.5]),
        (MapNorm::Channel, [2.0, 4.0, 6.0], [1.0; 3]),
    ] {
        let input = LightInput::new(&map, 37.0, 64, norm);
        for k in 0..3 {
            assert!((input.scale[k] - scale[k]).abs() < 1e-5, "{norm:?}");
            let channel = &input.pixels[k * 64 * 32..(k + 1) * 64 * 32];
            assert!(channel.iter().all(|v| (v - expect[k].ln_1p()).abs() < 1e-5));
        }
    }
    // A bright texel moves by the rotation: a quarter turn shifts it by a quarter of the width.
    let mut texels = vec![glam::Vec3::splat(0.1); 256 * 128];
    texels[64 * 256 + 32] = glam::Vec3::new(1000.0, 600.0, 300.0);
    let map = EnvMap::from_texels("spot", 256, 128, texels).unwrap();
    // A tint (a gain per channel) reaches the per-channel encoder input only through its scale.
    let gain = glam::Vec3::new(2.0, 1.0, 0.25);
    let tinted = map.scaled(gain).unwrap();
    let (a, b) = (
        LightInput::new(&map, 10.0, 64, MapNorm::Channel),
        LightInput::new(&tinted, 10.0, 64, MapNorm::Channel),
    );
    let most = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max);
    assert!(most < 1e-5, "per-channel input moved by {most}");
    for k in 0..3 {
        assert!((b.scale[k] / a.scale[k] - gain[k]).abs() < 1e-5);
    }
    let mean = |m: &EnvMap| LightInput::new(m, 10.0, 64, MapNorm::Mean).pixels;
    assert!(
        mean(&map) != mean(&tinted),
        "the paper's input sees the tint"
    );
    let peak = |rot: f32| {
        let p = LightInput::new(&map, rot, 64, MapNorm::Mean).pixels;
        (0..64 * 32).max_by(|&a, &b| p[a].total_cmp(&p[b])).unwrap()
    };
    let (a, b) = (peak(0.0), peak(90.0));
    assert_eq!(a / 64, b / 64, "same row");
    let shift = (b % 64 + 64 - a % 64) % 64;
    assert_eq!(shift.min(64 - shift), 16, "{a} → {b}");
}

/// With per-channel normalisation every design's prediction follows a tint of the map exactly:
/// the same radiance, each channel times its gain. With the paper's single mean it does not.
#[test]
fn per_channel_models_relight_a_tinted_map_by_its_tint() {
    use nprt_net::{LightInput, MapNorm};
    let device = Device::flex();
    let mut texels = vec![glam::Vec3::new(0.2, 0.3, 0.5); 128 * 64];
    texels[20 * 128 + 40] = glam::Vec3::new(900.0, 700.0, 400.0);
    let map = nprt_scene::envmap::EnvMap::from_texels("sun", 128, 64, texels).unwrap();
    let gain = glam::Vec3::new(1.8, 1.0, 0.3);
    let tinted = map.scaled(gain).unwrap();
    let n = 8;
    let features = tiny_batch(&Init::new(0, &device), n, 9).features;
    for design in Design::ALL {
        for norm in MapNorm::ALL {
            let config = ModelConfig {
                encoder_width: 64,
                map_norm: norm,
                ..ModelConfig::new(design, None)
            };
            let net = config.build(&mut Init::new(5, &device));
            let shade = |m: &nprt_scene::envmap::EnvMap| {
                let input = LightInput::new(m, 0.0, 64, norm);
                let pred = net.forward(
                    features.clone(),
                    Tensor::from_data(TensorData::new(input.pixels, [1, 3, 32, 64]), &device),
                    Tensor::from_data(TensorData::new(vec![0i64; n], [n]), &device),
                    Tensor::from_data(TensorData::new(input.scale.repeat(n), [n, 3]), &device),
                );
                nprt_net::host_values(pred.into_data())
            };
            let (a, b) = (shade(&map), shade(&tinted));
            let worst = (0..n * 3)
                .map(|i| (b[i] / (a[i] * gain[i % 3]) - 1.0).abs())
                .fold(0.0f32, f32::max);
            match norm {
                MapNorm::Channel => assert!(worst < 1e-4, "{design:?}: off by {worst}"),
                MapNorm::Mean => assert!(worst > 1e-2, "{design:?}: the mean is blind to tint"),
            }
        }
    }
}

/// The CPU engine's loss and gradients against burn's autodiff on the same batch, for every
/// design and activation (the batch: [`random_batch`]). Both f32 paths are measured against burn in
/// f64, and the engine's error must stay within twice burn's own f32 error (plus 1e-6 of the
/// gradient's norm): where ReLU units sit within rounding of zero, both f32 paths differ from
/// the exact gradient, and from each other, by more than rounding. The transport networks are
/// held to that on burn's light codes; the encoder in `host_encoder_matches_autodiff`.
#[test]
fn cpu_engine_matches_autodiff() {
    let device = Device::flex().autodiff();
    let (batch, w) = (random_batch(1100, 3, 21), 64);
    for variant in variants() {
        let name = format!("{}/{:?}", variant.label(), variant.activation);
        let config = ModelConfig {
            encoder_width: w,
            ..variant
        };
        for objective in Loss::ALL {
            let net = loud_grids(config.build(&mut Init::new(4, &device)));
            assert!(nprt_net::cpu::applies(&net));
            let (burn_loss, burn) =
                batch.gradients(&net, &device, nprt_net::GradientPath::Autodiff, objective);
            // The transport networks on burn's light codes, whose gradient at the codes burn
            // then carries through the encoder: every gradient held to f32 rounding.
            let codes = net.encoder.forward(batch.light_tensor(&device));
            let host_codes = nprt_net::host_values(codes.clone().into_data());
            let (loss, mut engine, d_codes) = nprt_net::cpu::transport_gradients(
                &net,
                &batch.samples(),
                &host_codes,
                &device,
                objective,
            );
            let d_codes = Tensor::<2>::from_data(TensorData::new(d_codes, codes.dims()), &device);
            let through = (codes * d_codes).sum().backward();
            let mut encoder = Shapes(Vec::new());
            net.encoder.visit(&mut encoder);
            let through = GradientsParams::from_grads(through, &net);
            for (id, dims) in &encoder.0 {
                match dims.len() {
                    1 => engine.register::<1>(*id, through.get::<1>(*id).unwrap()),
                    2 => engine.register::<2>(*id, through.get::<2>(*id).unwrap()),
                    _ => engine.register::<4>(*id, through.get::<4>(*id).unwrap()),
                }
            }
            assert!(
                (loss - burn_loss).abs() <= 1e-6 * burn_loss,
                "{name}/{objective:?}: loss {loss} vs {burn_loss}"
            );
            let (_, exact) = exact_gradients(&config, &batch, objective);
            for e in gradient_errors(&net, &exact, [&engine, &burn]) {
                let (ours, theirs) = (e.errors[0], e.errors[1]);
                assert!(
                    ours <= 2.0 * theirs + 1e-6 * e.norm,
                    "{name}/{objective:?} param {} {:?}: engine error {ours:e}, burn f32 error {theirs:e}, gradient norm {:e}",
                    e.id, e.dims, e.norm
                );
            }
            // The whole step, the encoder on the engine too (held to rounding by
            // `host_encoder_matches_autodiff`). Its codes differ from burn's by f32 rounding,
            // enough to move the odd ReLU pre-activation across zero and with it one sample's
            // share of a gradient (measured: up to 6e-4 of a gradient's norm): a check that
            // every gradient is filed where it belongs, not of rounding.
            let (loss, whole) =
                nprt_net::cpu::gradients(&net, &batch.samples(), &device, objective);
            assert!((loss - burn_loss).abs() <= 1e-5 * burn_loss);
            for e in gradient_errors(&net, &exact, [&whole]) {
                assert!(
                    e.errors[0] <= 1e-2 * e.norm,
                    "{name}/{objective:?} whole step, param {} {:?}: error {:e}, norm {:e}",
                    e.id,
                    e.dims,
                    e.errors[0],
                    e.norm
                );
            }
        }
    }
}

/// The CPU engine's light encoder against burn's autodiff, in f32 and in f64, for the same
/// gradient at the codes: codes, and every weight's gradient.
#[test]
fn host_encoder_matches_autodiff() {
    let device = Device::flex().autodiff();
    let batch = random_batch(8, 3, 23);
    let (views, w) = (3, batch.light_width);
    let config = ModelConfig {
        encoder_width: w,
        ..ModelConfig::new(Design::Prt, None)
    };
    let mut rng = Pcg64Mcg::seed_from_u64(24);
    let d_codes: Vec<f32> = (0..views * 64).map(|_| rng.random::<f32>() - 0.5).collect();
    let burn = |dtype: DType| {
        let mut init = Init::with_dtype(4, &device, dtype);
        let net = config.build(&mut init);
        let lights = init.tensor(batch.lights.clone(), [views, 3, w / 2, w]);
        let codes = net.encoder.forward(lights);
        let d = init.tensor(d_codes.clone(), [views, 64]);
        let grads = GradientsParams::from_grads((codes.clone() * d).sum().backward(), &net);
        (
            net,
            codes
                .into_data()
                .convert::<f64>()
                .try_to_vec::<f64>()
                .unwrap(),
            grads,
        )
    };
    let (net, burn_codes, burn_grads) = burn(DType::F32);
    let (_, exact_codes, exact) = burn(DType::F64);
    let host = nprt_net::cpu::HostEncoder::from_burn(&net.encoder);
    let pass = host.forward(&batch.lights, w);
    let error = |codes: &[f64]| -> f64 {
        codes
            .iter()
            .zip(&exact_codes)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let ours: Vec<f64> = pass.codes.iter().map(|&c| c as f64).collect();
    assert!(
        error(&ours) <= 2.0 * error(&burn_codes) + 1e-7,
        "codes: {:e} against burn's {:e}",
        error(&ours),
        error(&burn_codes)
    );
    let mut ours = GradientsParams::new();
    let g = host.backward(&pass, &d_codes);
    nprt_net::cpu::register_encoder(&mut ours, &net.encoder, g, &Device::flex());
    let errors = gradient_errors(&net.encoder, &exact, [&ours, &burn_grads]);
    assert_eq!(
        errors.len(),
        12,
        "5 convolutions and the code layer, with biases"
    );
    for e in errors {
        let (ours, theirs) = (e.errors[0], e.errors[1]);
        assert!(
            ours <= 2.0 * theirs + 1e-6 * e.norm,
            "{:?}: engine error {ours:e}, burn f32 error {theirs:e}, norm {:e}",
            e.dims,
            e.norm
        );
    }
}

/// `n` rows of features in [0, 1) and one light code in [-0.5, 0.5), seeded.
fn pixels_and_code(seed: u64, n: usize) -> (Vec<f32>, Vec<f32>) {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let features = (0..n * FEATURES).map(|_| rng.random::<f32>()).collect();
    let code = (0..64).map(|_| rng.random::<f32>() - 0.5).collect();
    (features, code)
}

/// Inference on the CPU engine, with and without the transfer outputs kept, against burn's
/// forward pass of the same network.
#[test]
fn cpu_engine_radiance_matches_burn() {
    let device = Device::flex();
    let n = 1300;
    let (features, code) = pixels_and_code(5, n);
    let scale = [1.7, 0.6, 2.3];
    for config in variants() {
        let name = config.label();
        let net = loud_grids(config.build(&mut Init::new(8, &device)));
        let want = net.shade(
            Tensor::from_data(TensorData::new(features.clone(), [n, FEATURES]), &device),
            Tensor::<2>::from_data(TensorData::new(code.clone(), [1, 64]), &device).expand([n, 64]),
            Tensor::from_data(TensorData::new(scale.repeat(n), [n, 3]), &device),
        );
        let want = nprt_net::host_values(want.into_data());
        let host = nprt_net::cpu::HostTransport::from_net(&net);
        let kept = host.transfer_codes(&features);
        for got in [
            host.radiance(&features, &code, scale, None),
            host.radiance(&features, &code, scale, Some(&kept)),
        ] {
            let worst = got
                .iter()
                .zip(&want)
                .map(|(a, b)| (a - b).abs() / b.abs().max(1e-3))
                .fold(0.0f32, f32::max);
            assert!(worst < 1e-5, "{name}: relative difference {worst}");
        }
    }
}

/// Starting a network at the data's level scales every design's untrained radiance by exactly
/// exp(level), in burn and in the CPU engine alike (the shift lives in the output bias).
#[test]
fn output_level_shift_scales_the_untrained_prediction() {
    let device = Device::flex();
    let n = 200;
    let (features, code) = pixels_and_code(9, n);
    let level = (2e-3f32).ln();
    for design in Design::ALL {
        let net = ModelConfig::new(design, None).build(&mut Init::new(8, &device));
        let shifted = net.clone().shift_output_level(level);
        let radiance = |net: &NprtNet| {
            nprt_net::cpu::HostTransport::from_net(net).radiance(&features, &code, [1.0; 3], None)
        };
        for (a, b) in radiance(&shifted).iter().zip(radiance(&net)) {
            assert!(
                (a / b - 2e-3).abs() < 1e-3 * 2e-3,
                "{design:?}: {a} is not 2e-3 × {b}"
            );
        }
    }
}
