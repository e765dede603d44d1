//! The GPU code path (burn's cubecl kernels, the ones CUDA runs, with data moved to and from a
//! device) on wgpu, here on a software Vulkan device (Mesa's lavapipe, installed by
//! scripts/vulkan.sh), so that it is tested on machines without a GPU. Its own test binary:
//! choosing a device sets burn's default device for the whole process.
//!
//! Without a Vulkan driver these tests skip, unless NPRT_REQUIRE_VULKAN is set (scripts/test
//! sets it once lavapipe is installed).

mod common;

use burn::module::Module;
use burn::optim::AdamConfig;
use common::{exact_gradients, gradient_errors, loud_grids, random_batch, variants};
use nprt_net::model::folder::{load_weights, save_weights};
use nprt_net::{Compute, Design, Device, Engine, Init, Loss, ModelConfig, NprtNet};

/// The wgpu device, or None (test skipped) where there is none and none is required.
fn gpu() -> Option<Device> {
    match Compute::Wgpu.device() {
        Ok(device) => Some(device),
        Err(e) if std::env::var_os("NPRT_REQUIRE_VULKAN").is_none() => {
            eprintln!("skipped: {e}");
            None
        }
        Err(e) => panic!("NPRT_REQUIRE_VULKAN is set but {e}"),
    }
}

/// Predictions of `net` on `batch` as host values.
fn predict(net: &NprtNet, batch: &nprt_net::Batch, device: &Device) -> Vec<f32> {
    batch
        .forward(net, device)
        .0
        .into_data()
        .try_to_vec::<f32>()
        .unwrap()
}

/// Largest difference between `a` and `b` relative to b's largest magnitude.
fn relative_difference(a: &[f32], b: &[f32]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs() as f64));
    let diff = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs() as f64));
    diff / scale
}

/// Every design, activation and encoding, with each loss: the GPU path's prediction, loss and
/// gradients against the CPU's (burn's graph on both) and against burn in f64. Predictions
/// must agree within 1e-5 of their largest value, and the GPU's gradient error stay within
/// 1e-5 of each gradient's norm plus twice the CPU's own f32 error: its sums run in another
/// order, and its sin and exp are the driver's, not libm's. On lavapipe the largest seen were
/// 2.4e-6 and 1.2e-6.
#[test]
fn the_gpu_path_matches_the_cpu_for_every_design() {
    let Some(gpu) = gpu() else { return };
    let (gpu, cpu) = (gpu.autodiff(), Device::flex().autodiff());
    let batch = random_batch(256, 3, 22);
    for variant in variants() {
        let name = format!("{}/{:?}", variant.label(), variant.activation);
        let config = ModelConfig {
            encoder_width: 64,
            ..variant
        };
        let on_gpu = loud_grids(config.build(&mut Init::new(4, &gpu)));
        let on_cpu = loud_grids(config.build(&mut Init::new(4, &cpu)));
        let forward = relative_difference(
            &predict(&on_gpu.valid(), &batch, &gpu.clone().inner()),
            &predict(&on_cpu.valid(), &batch, &cpu.clone().inner()),
        );
        assert!(forward < 1e-5, "{name}: predictions differ by {forward:e}");
        for objective in Loss::ALL {
            let (gpu_loss, on_gpu_grads) =
                batch.gradients(&on_gpu, &gpu, Engine::Autodiff, objective);
            let (cpu_loss, on_cpu_grads) =
                batch.gradients(&on_cpu, &cpu, Engine::Autodiff, objective);
            assert!(
                (gpu_loss - cpu_loss).abs() <= 1e-5 * cpu_loss,
                "{name}/{objective:?}: loss {gpu_loss} on the GPU, {cpu_loss} on the CPU"
            );
            let (_, exact) = exact_gradients(&config, &batch, objective);
            for e in gradient_errors(&on_cpu, &exact, [&on_gpu_grads, &on_cpu_grads]) {
                let (gpu_error, cpu_error) = (e.errors[0], e.errors[1]);
                assert!(
                    gpu_error <= 2.0 * cpu_error + 1e-5 * e.norm,
                    "{name}/{objective:?} param {} {:?}: GPU error {gpu_error:e}, CPU f32 error {cpu_error:e}, gradient norm {:e}",
                    e.id,
                    e.dims,
                    e.norm
                );
            }
        }
    }
    nprt_net::finish();
}

/// Weights trained on one device load on the other and predict the same there: the model
/// folder does not depend on the device that wrote it.
#[test]
fn weights_trained_on_either_device_predict_the_same_on_the_other() {
    let Some(gpu) = gpu() else { return };
    let cpu = Device::flex();
    let dir = std::env::temp_dir().join(format!("nprt-software-gpu-{}", std::process::id()));
    let batch = random_batch(300, 2, 23);
    let config = ModelConfig {
        encoder_width: 64,
        ..ModelConfig::new(Design::Dsep, None)
    };
    for (from, to) in [(&gpu, &cpu), (&cpu, &gpu)] {
        let device = from.clone().autodiff();
        let mut net = config.build(&mut Init::new(5, &device));
        let mut optim = AdamConfig::new().init();
        for _ in 0..5 {
            let (_, grads) = batch.gradients(&net, &device, Engine::Auto, Loss::LogL1);
            net = optim.step(1e-3, net, grads);
        }
        let trained = net.valid();
        let path = dir.join("dsep.safetensors");
        save_weights(&path, &trained, "dsep").unwrap();
        let mut loaded = config.build(&mut Init::new(6, to));
        load_weights(&path, &mut loaded, "dsep").unwrap();
        let there = predict(&loaded, &batch, to);
        let here = predict(&trained, &batch, from);
        let untrained = predict(&config.build(&mut Init::new(5, from)), &batch, from);
        assert!(
            relative_difference(&untrained, &here) > 1e-3,
            "five steps change the prediction"
        );
        let diff = relative_difference(&there, &here);
        assert!(
            diff < 1e-5,
            "{from:?} → {to:?}: predictions differ by {diff:e}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
    nprt_net::finish();
}
