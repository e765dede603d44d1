//! Networks: parameter counts, the CPU engine's gradients against finite differences of an f64
//! reference, its inference against the reference, weight round-trips.

#[allow(dead_code)] // the helpers other test binaries use
mod common;

use common::reference::Reference;
use common::{check_against, check_gradients, loud_grids, random_batch, variants};
use nprt_net::model::folder::{load_weights, save_weights};
use nprt_net::FEATURES;
use nprt_net::{cpu, Activation, Batch, Design, Init, Loss, ModelConfig, NprtNet, Parameters};
use nprt_net::{BasisChoice, PositionEncoding};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

#[test]
fn transport_parameter_counts_are_the_papers() {
    for design in Design::PAPER {
        for activation in [Activation::Siren, Activation::Relu] {
            let net = ModelConfig::new(design, Some(activation)).build(&mut Init::new(0));
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

/// The CPU engine's gradients of every tensor of every design (encoder included, hash grid
/// where there is one) against central differences of the f64 reference's loss, for both
/// losses, on a tiny batch of two maps. The encoder is the same in every design: it is checked
/// on the first.
#[test]
fn gradients_match_finite_differences() {
    let batch = random_batch(6, 2, 5);
    for (v, variant) in variants().into_iter().enumerate() {
        let config = ModelConfig {
            encoder_width: 64,
            ..variant
        };
        let net = loud_grids(config.build(&mut Init::new(3)));
        for loss in Loss::ALL {
            let name = format!("{}/{:?}/{loss:?}", config.label(), config.activation);
            let (_, grads) = cpu::gradients(&net, &batch.samples(), loss);
            // The encoder is the same in every design; a learned basis is checked where it is.
            let light = v == 0 || config.basis.is_some_and(|b| b.is_learned());
            check_gradients(&name, &net, &batch, loss, &grads, light);
        }
    }
}

/// Transfer targets (`--targets transfer`): the CPU engine's gradients of the mean squared
/// error of the linear design's transfer vectors, against central differences of the f64
/// reference's, whose vector is its radiance under each basis function alone as the light
/// code (scale 1); every track's tensors, with and without a hash grid.
#[test]
fn transfer_gradients_match_finite_differences() {
    let mut batch = random_batch(6, 2, 11);
    for band in [1usize, 2] {
        let k = (band + 1) * (band + 1);
        let mut rng = Pcg64Mcg::seed_from_u64(band as u64);
        batch.transfer = (0..batch.len() * 3 * k)
            .map(|_| rng.random::<f32>() - 0.3)
            .collect();
        for encoding in [PositionEncoding::None, PositionEncoding::HashGrid] {
            let config = ModelConfig {
                encoder_width: 64,
                basis: Some(BasisChoice::Sh { band }),
                encoding,
                ..ModelConfig::new(Design::Linear, None)
            };
            let net = loud_grids(config.build(&mut Init::new(5)));
            let (loss, grads) = cpu::gradients(&net, &batch.samples(), Loss::LogL1);
            let reference = Reference::new(&net);
            let unlit = Batch {
                features: batch.features.clone(),
                radiance: batch.radiance.clone(),
                transfer: Vec::new(),
                view: vec![0; batch.len()],
                scale: vec![1.0; batch.len() * 3],
                lights: Vec::new(),
                light_width: 64,
                picks: None,
            };
            let value = |r: &Reference, _| {
                let mut sum = 0.0;
                for j in 0..k {
                    let mut code = vec![0.0; 3 * k];
                    code[3 * j..3 * j + 3].fill(1.0);
                    let p = r.predict(&unlit, Some(&[code]));
                    for (i, p) in p.iter().enumerate() {
                        let want = batch.transfer[(i / 3 * k + j) * 3 + i % 3] as f64;
                        sum += (p - want).powi(2);
                    }
                }
                sum / batch.transfer.len() as f64
            };
            let name = format!("sh:{band} {encoding:?}");
            assert!(
                (loss - value(&reference, 0)).abs() < 1e-5 * loss,
                "{name}: {loss}"
            );
            check_against(&name, reference, &grads, 0, value);
        }
    }
}

/// Mean |log(1 + p) − log(1 + r)| of the CPU engine's prediction on `batch`.
fn log_l1(net: &NprtNet, batch: &Batch) -> f64 {
    Loss::LogL1.mean(&cpu::predict(net, &batch.samples()), &batch.radiance)
}

#[test]
fn saved_weights_load_into_a_fresh_network_exactly() {
    let dir = std::env::temp_dir().join(format!("nprt-net-weights-{}", std::process::id()));
    for design in Design::ALL {
        let config = ModelConfig {
            encoder_width: 64,
            ..ModelConfig::new(design, None)
        };
        let batch = random_batch(16, 2, 2);
        let net = config.build(&mut Init::new(1));
        let path = dir.join(format!("{}.safetensors", design.name()));
        save_weights(&path, &net, design.name()).unwrap();
        let mut other = config.build(&mut Init::new(2));
        let before = log_l1(&other, &batch);
        load_weights(&path, &mut other, design.name()).unwrap();
        assert_eq!(other, net);
        assert_ne!(
            before,
            log_l1(&net, &batch),
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
        .build(&mut Init::new(1));
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
    use nprt_net::MapNorm;
    let mut texels = vec![glam::Vec3::new(0.2, 0.3, 0.5); 128 * 64];
    texels[20 * 128 + 40] = glam::Vec3::new(900.0, 700.0, 400.0);
    let map = nprt_scene::envmap::EnvMap::from_texels("sun", 128, 64, texels).unwrap();
    let gain = glam::Vec3::new(1.8, 1.0, 0.3);
    let tinted = map.scaled(gain).unwrap();
    let n = 8;
    let features = random_batch(n, 1, 9).features;
    for design in Design::ALL {
        for norm in MapNorm::ALL {
            let config = ModelConfig {
                encoder_width: 64,
                map_norm: norm,
                ..ModelConfig::new(design, None)
            };
            let net = config.build(&mut Init::new(5));
            let shade = |m: &nprt_scene::envmap::EnvMap| {
                let input = config.light_input(m, 0.0);
                let code = net
                    .light
                    .forward(&input.pixels, input.width)
                    .codes()
                    .to_vec();
                net.radiance(&features, &code, input.scale, None)
            };
            let (a, b) = (shade(&map), shade(&tinted));
            let worst = (0..n * 3)
                .map(|i| (b[i] / (a[i] * gain[i % 3]) - 1.0).abs())
                .fold(0.0f32, f32::max);
            // A design linear in the lighting follows any gain, whatever the normalisation.
            match (norm, design.linear_in_light()) {
                (MapNorm::Channel, _) | (_, true) => {
                    assert!(worst < 1e-4, "{design:?}/{norm}: off by {worst}")
                }
                (MapNorm::Mean, false) => {
                    assert!(worst > 1e-2, "{design:?}: the mean is blind to tint")
                }
            }
        }
    }
}

/// The CPU engine on a batch of many blocks, runs and maps, every design, both losses: its
/// prediction and loss against the f64 reference, and its gradient against the gradients of
/// the batch's two halves, weighted by their sizes (the mean's gradient is that sum): the
/// blocks, runs and maps are each filed where they belong. The halves' own gradients are
/// checked by `gradients_match_finite_differences`.
#[test]
fn cpu_engine_matches_the_reference_on_a_large_batch() {
    let (batch, w) = (random_batch(1100, 3, 21), 64);
    let half = |range: std::ops::Range<usize>| Batch {
        features: batch.features[range.start * FEATURES..range.end * FEATURES].to_vec(),
        radiance: batch.radiance[range.start * 3..range.end * 3].to_vec(),
        transfer: Vec::new(),
        view: batch.view[range.clone()].to_vec(),
        scale: batch.scale[range.start * 3..range.end * 3].to_vec(),
        lights: batch.lights.clone(),
        light_width: w,
        picks: None,
    };
    let (a, b) = (half(0..700), half(700..1100));
    for variant in variants() {
        let name = format!("{}/{:?}", variant.label(), variant.activation);
        let config = ModelConfig {
            encoder_width: w,
            ..variant
        };
        let net = loud_grids(config.build(&mut Init::new(4)));
        let want = Reference::new(&net).predict(&batch, None);
        let got = cpu::predict(&net, &batch.samples());
        let floor = relative_floor(&config, &want);
        let worst = (got.iter().zip(&want))
            .map(|(&g, &w)| (g as f64 - w).abs() / w.abs().max(floor))
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-4,
            "{name}: prediction off by {worst:e} (relative)"
        );
        for loss in Loss::ALL {
            let (value, whole) = cpu::gradients(&net, &batch.samples(), loss);
            let reference = Reference::new(&net).loss(&batch, loss, None, &want);
            assert!(
                (value - reference).abs() <= 1e-5 * reference,
                "{name}/{loss:?}: loss {value} vs {reference}"
            );
            let (_, ga) = cpu::gradients(&net, &a.samples(), loss);
            let (_, gb) = cpu::gradients(&net, &b.samples(), loss);
            let (sum, whole) = (combined(&ga, 700.0, &gb, 400.0), whole.flat());
            let mut at = 0;
            net.visit("", &mut |tensor, _, v| {
                let (x, y) = (&whole[at..at + v.len()], &sum[at..at + v.len()]);
                at += v.len();
                let norm = y.iter().map(|v| v * v).sum::<f64>().sqrt();
                let error = (x.iter().zip(y))
                    .map(|(&x, &y)| (x as f64 - y).powi(2))
                    .sum::<f64>()
                    .sqrt();
                assert!(
                    error <= 1e-4 * norm + 1e-9,
                    "{name}/{loss:?} {tensor}: whole batch off its halves by {error:e} (norm {norm:e})"
                );
            });
        }
    }
}

/// The smallest magnitude a relative error is taken against: 10⁻³, or for a design with a track
/// linear in the lighting, whose radiance is a dot product that cancels through zero where its
/// exps could not, 10% of the largest value (f32's rounding of the terms, not of their sum,
/// sets its error).
fn relative_floor(config: &ModelConfig, values: &[f64]) -> f64 {
    let combines = config.design.entries(1).iter().any(|e| e.after_networks());
    match combines {
        true => 0.1 * values.iter().fold(0.0f64, |m, v| m.max(v.abs())),
        false => 1e-3,
    }
}

/// (n_a · a + n_b · b) / (n_a + n_b), flat, in f64.
fn combined(a: &NprtNet, n_a: f64, b: &NprtNet, n_b: f64) -> Vec<f64> {
    (a.flat().iter().zip(b.flat()))
        .map(|(&x, y)| (n_a * x as f64 + n_b * y as f64) / (n_a + n_b))
        .collect()
}

/// `n` rows of features in [0, 1) and one light code in [-0.5, 0.5), seeded: as long as the
/// largest code of the tests' networks, each taking what it needs from the start.
fn pixels_and_code(seed: u64, n: usize) -> (Vec<f32>, Vec<f32>) {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let features = (0..n * FEATURES).map(|_| rng.random::<f32>()).collect();
    let code = (0..256).map(|_| rng.random::<f32>() - 0.5).collect();
    (features, code)
}

/// Inference on the CPU engine for one light code, with and without the transfer outputs
/// kept, against the f64 reference.
#[test]
fn cpu_engine_radiance_matches_the_reference() {
    let n = 1300;
    let (features, code) = pixels_and_code(5, n);
    let scale = [1.7, 0.6, 2.3];
    let batch = Batch {
        features: features.clone(),
        radiance: vec![0.0; 3 * n],
        transfer: Vec::new(),
        view: vec![0; n],
        scale: scale.repeat(n),
        lights: Vec::new(),
        light_width: 64,
        picks: None,
    };
    for config in variants() {
        let name = config.label();
        let net = loud_grids(config.build(&mut Init::new(8)));
        let code = &code[..net.light.code_size()];
        let codes = [code.iter().map(|&c| c as f64).collect::<Vec<f64>>()];
        let want = Reference::new(&net).predict(&batch, Some(&codes));
        let kept = net.kept_rows(&features);
        for got in [
            net.radiance(&features, code, scale, None),
            net.radiance(&features, code, scale, Some(&kept)),
        ] {
            let floor = relative_floor(&config, &want);
            let worst = (got.iter().zip(&want))
                .map(|(&a, &b)| (a as f64 - b).abs() / b.abs().max(floor))
                .fold(0.0, f64::max);
            assert!(worst < 1e-5, "{name}: relative difference {worst}");
        }
    }
}

/// Starting a network at the data's level scales every design's untrained radiance by exactly
/// exp(level) (the shift lives in the output bias).
#[test]
fn output_level_shift_scales_the_untrained_prediction() {
    let n = 200;
    let (features, code) = pixels_and_code(9, n);
    let level = (2e-3f32).ln();
    for design in Design::PAPER {
        let net = ModelConfig::new(design, None).build(&mut Init::new(8));
        let shifted = net.clone().shift_output_level(level);
        let code = &code[..net.light.code_size()];
        let radiance = |net: &NprtNet| net.radiance(&features, code, [1.0; 3], None);
        for (a, b) in radiance(&shifted).iter().zip(radiance(&net)) {
            assert!(
                (a / b - 2e-3).abs() < 1e-3 * 2e-3,
                "{design:?}: {a} is not 2e-3 × {b}"
            );
        }
    }
}

/// The linear design's outputs are coefficients, not log-radiance: its shift adds exp(level) to
/// the radiance of a pixel of albedo ½ under a map of mean 1 (the constant function's
/// coefficient √(4π), every other zero).
#[test]
fn the_linear_designs_level_shift_adds_the_level() {
    use nprt_net::encoding::features::feature;
    let n = 50;
    let (mut features, _) = pixels_and_code(9, n);
    for f in features.chunks_exact_mut(FEATURES) {
        f[feature::KD].fill(0.5);
        f[feature::KS].fill(0.5);
    }
    let net = ModelConfig::new(Design::Linear, None).build(&mut Init::new(8));
    let mut code = vec![0.0; net.light.code_size()];
    code[..3].fill((4.0 * std::f32::consts::PI).sqrt());
    let level = 0.7f32.ln();
    let shifted = net.clone().shift_output_level(level);
    let radiance = |net: &NprtNet| net.radiance(&features, &code, [1.0; 3], None);
    for (a, b) in radiance(&shifted).iter().zip(radiance(&net)) {
        assert!((a - b - 0.7).abs() < 1e-5, "{a} − {b} is not 0.7");
    }
}

/// The weights file is the model folder's contract: every design's header (tensor names,
/// shapes, order and offsets) and the Deep Shading U-Net's is byte for byte the one burn wrote
/// before nprt had its own weight type (tests/data/weights_headers.json, from `nprt demo
/// --quick` at stop 46), so model folders written before still load.
#[test]
fn weights_files_have_the_headers_models_were_written_with() {
    use nprt_net::deep_shading::DeepShading;
    let golden: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(include_str!("data/weights_headers.json")).unwrap();
    let dir = std::env::temp_dir().join(format!("nprt-net-headers-{}", std::process::id()));
    for (tag, header) in &golden {
        let path = dir.join(format!("{}.safetensors", tag.replace(':', "-")));
        match tag.split_once(':') {
            None => save_weights(&path, &DeepShading::new(&mut Init::new(0), 128), tag),
            Some((design, activation)) => {
                let design = *Design::ALL.iter().find(|d| d.name() == design).unwrap();
                let activation = [Activation::Siren, Activation::Relu]
                    .into_iter()
                    .find(|a| a.name() == activation);
                let net = ModelConfig::new(design, activation).build(&mut Init::new(0));
                save_weights(&path, &net, tag)
            }
        }
        .unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let n = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
        let written = std::str::from_utf8(&bytes[8..8 + n]).unwrap();
        assert_eq!(written, header.as_str().unwrap(), "{tag}");
    }
    // The paper's four designs' headers and the U-Net's: a design added since has none.
    assert_eq!(golden.len(), Design::PAPER.len() + 1);
    std::fs::remove_dir_all(&dir).ok();
}

/// Every named choice of the networks and their training (`nprt_engine::named_choice!`), held
/// to its names: parsed back, through serde as model.json writes them, and an unknown name
/// answered with the accepted ones.
mod choices {
    use nprt_net::PositionEncoding;
    use nprt_net::{
        Activation, Calibration, Compute, Design, DirectLight, Loss, LrSchedule, MapNorm,
    };

    /// Every choice's name parses back and round-trips through serde (model.json).
    fn round_trips<T>(all: &[T])
    where
        T: Copy + PartialEq + std::fmt::Debug + std::fmt::Display + std::str::FromStr,
        T: serde::Serialize + serde::de::DeserializeOwned,
        <T as std::str::FromStr>::Err: std::fmt::Debug,
    {
        for &c in all {
            assert_eq!(c.to_string().parse::<T>().unwrap(), c);
            let json = serde_json::to_string(&c).unwrap();
            assert_eq!(json, format!("\"{c}\""));
            assert_eq!(serde_json::from_str::<T>(&json).unwrap(), c);
        }
    }

    #[test]
    fn names_parse_and_unknown_ones_list_the_choices() {
        round_trips(&Loss::ALL);
        round_trips(&MapNorm::ALL);
        round_trips(&DirectLight::ALL);
        round_trips(&Calibration::ALL);
        round_trips(&PositionEncoding::ALL);
        round_trips(&Design::ALL);
        round_trips(&Activation::ALL);
        round_trips(&LrSchedule::ALL);
        round_trips(&Compute::ALL);
        let err = "mean".parse::<Calibration>().unwrap_err().to_string();
        assert_eq!(err, "unknown calibration 'mean' (expected none or level)");
        let err = "l2".parse::<Loss>().unwrap_err().to_string();
        assert_eq!(err, "unknown loss 'l2' (expected log-l1 or rel-l2)");
        let err = "max".parse::<MapNorm>().unwrap_err().to_string();
        assert_eq!(
            err,
            "unknown map normalisation 'max' (expected mean or channel)"
        );
        // A list of three or more: commas, then "or" (the designs' names, whatever they are).
        let err = serde_json::from_str::<Design>("\"mlp\"")
            .unwrap_err()
            .to_string();
        let names = Design::ALL.map(Design::name);
        let (last, rest) = names.split_last().unwrap();
        let want = format!(
            "unknown design 'mlp' (expected {} or {last})",
            rest.join(", ")
        );
        assert!(rest.len() >= 2 && err.contains(&want), "{err}");
    }
}
