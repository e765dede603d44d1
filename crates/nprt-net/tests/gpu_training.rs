//! The GPU training step (nprt-net's own kernels, `gpu::GpuTrainer`) against the CPU engine
//! it must agree with: loss, every parameter's gradient and the light codes' gradient for
//! every design, activation and encoding, both losses; one Adam step against burn's. Runs on
//! whatever adapter wgpu finds; CI's is Mesa's software Vulkan (scripts/vulkan.sh). Without
//! one the tests skip, unless NPRT_REQUIRE_VULKAN is set (scripts/test sets it once lavapipe
//! is installed).
#![cfg(feature = "kernels")]

#[allow(dead_code)] // the helpers other test binaries use
mod common;

use common::{loud_grids, random_batch, variants};
use nprt_net::cpu::{HostEncoder, HostTransport};
use nprt_net::gpu::{GpuDevice, GpuTrainer, ParameterLayout};
use nprt_net::{Device, Init, Loss, NprtNet};

/// Whether a GPU adapter is here; panics where one is required and missing.
fn gpu_present() -> bool {
    match GpuDevice::get() {
        Ok(gpu) => {
            eprintln!("adapter: {}", gpu.adapter);
            true
        }
        Err(e) if std::env::var_os("NPRT_REQUIRE_VULKAN").is_none() => {
            eprintln!("skipped: {e:#}");
            false
        }
        Err(e) => panic!("NPRT_REQUIRE_VULKAN is set but {e:#}"),
    }
}

/// Euclidean distance of `a` from `b` over b's norm.
fn relative_error(a: &[f32], b: &[f32]) -> f64 {
    assert_eq!(a.len(), b.len());
    let d: f64 = a.iter().zip(b).map(|(x, y)| ((x - y) as f64).powi(2)).sum();
    let n: f64 = b.iter().map(|y| (*y as f64).powi(2)).sum();
    (d / n.max(1e-30)).sqrt()
}

/// Each tensor's relative error between two sets of values of one network's shapes.
fn tensor_errors(a: &(HostEncoder, HostTransport), b: &(HostEncoder, HostTransport)) -> Vec<f64> {
    let (layout, fa) = ParameterLayout::pack(&a.0, &a.1, 1);
    let (_, fb) = ParameterLayout::pack(&b.0, &b.1, 1);
    layout
        .spans
        .iter()
        .map(|s| relative_error(&fa[s.offset..][..s.len], &fb[s.offset..][..s.len]))
        .collect()
}

fn network(config: &nprt_net::ModelConfig) -> NprtNet {
    loud_grids(config.build(&mut Init::new(4, &Device::flex())))
}

#[test]
fn gpu_transport_gradients_match_the_cpu_engine_for_every_design() {
    if !gpu_present() {
        return;
    }
    let batch = random_batch(300, 3, 22);
    let samples = batch.samples();
    for config in variants() {
        let net = network(&config);
        let encoder = HostEncoder::from_burn(&net.encoder);
        let codes = encoder.forward(samples.lights, samples.light_width).codes;
        for loss in [Loss::LogL1, Loss::RelL2] {
            let host = HostTransport::from_net(&net);
            let want = host.gradients(&samples, &codes, loss);
            let mut gpu = GpuTrainer::new(&net).unwrap();
            let (value, d_codes) = gpu.transport_gradients(&samples, &codes, loss);
            let (_, got) = gpu.gradients();
            let want_transport = HostTransport {
                tracks: want.tracks,
            };
            // The encoder has no gradient here; compare the transport tensors only.
            let errors = tensor_errors(&(encoder.clone(), got), &(encoder.clone(), want_transport));
            let skip = 2 * encoder.convs.len() + 2;
            let worst = errors[skip..].iter().fold(0.0f64, |m, &e| m.max(e));
            let loss_error = (value - want.loss).abs() / want.loss;
            let code_error = relative_error(&d_codes, &want.codes);
            eprintln!(
                "{} {loss}: loss {loss_error:.1e}, gradients {worst:.1e}, codes {code_error:.1e}",
                config.label()
            );
            assert!(
                loss_error < 1e-5,
                "{} {loss}: loss off by {loss_error}",
                config.label()
            );
            assert!(
                worst < 1e-4,
                "{} {loss}: a gradient off by {worst}",
                config.label()
            );
            assert!(
                code_error < 1e-4,
                "{} {loss}: code gradient off by {code_error}",
                config.label()
            );
        }
    }
}
