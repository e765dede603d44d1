//! The radiance cache on the GPU kernels (`gpu::GpuCache`) against the CPU engine: its reads,
//! its loss and every weight's gradient, and Adam steps trained on either engine. Runs on
//! whatever adapter wgpu finds (CI's is lavapipe); without one the tests skip, unless
//! NPRT_REQUIRE_VULKAN is set.
#![cfg(feature = "gpu")]

#[allow(dead_code)] // the helpers other test binaries use
mod common;

use common::{cache_queries, relative_error, tensor_errors, update, worst};
use glam::Vec3;
use nprt_gpu::GpuDevice;
use nprt_net::gpu::GpuCache;
use nprt_net::network::radiance_cache::{RadianceCache, ADAM_BETAS};
use nprt_net::training::cache_trainer::CacheTrainer;
use nprt_net::{Engine, Init, Parameters};

fn targets(n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|i| Vec3::new(0.3, 0.5, 0.8) * (1.0 + (i % 7) as f32 * 0.2))
        .collect()
}

#[test]
fn gpu_cache_reads_and_gradients_match_the_cpu_engine() {
    if !GpuDevice::probe() {
        return;
    }
    // More rows than one read records at once, and a shorter last chunk.
    let q = cache_queries(5000, 9);
    let t = targets(q.len());
    let cache = RadianceCache::new(&mut Init::new(6));
    let mut gpu = GpuCache::new(&cache, ADAM_BETAS).unwrap();
    let flat = |v: &[Vec3]| -> Vec<f32> { v.iter().flat_map(|x| x.to_array()).collect() };
    let read_error = relative_error(&flat(&gpu.read(&q)), &flat(&cache.read(&q)));
    let (want_loss, want) = cache.loss_and_gradients(&q[..2048], &t[..2048]);
    let (loss, grads) = gpu.loss_and_gradients(&q[..2048], &t[..2048]);
    let errors = tensor_errors(&grads, &want);
    let worst = worst(&errors);
    let loss_error = (loss - want_loss).abs() / want_loss;
    eprintln!("reads {read_error:.1e}, loss {loss_error:.1e}, gradients {worst:.1e}");
    assert!(read_error < 1e-5, "reads off by {read_error}");
    assert!(loss_error < 1e-5, "loss off by {loss_error}");
    assert!(worst < 1e-4, "a gradient off: {errors:?}");
}

#[test]
fn training_on_the_kernels_follows_the_cpu_engine_step_by_step() {
    if !GpuDevice::probe() {
        return;
    }
    let q = cache_queries(3000, 10);
    let t = targets(q.len());
    let start = RadianceCache::new(&mut Init::new(7));
    let mut trained =
        [Engine::Cpu, Engine::Gpu].map(|e| CacheTrainer::new(start.clone(), 5e-3, e).unwrap());
    let losses = trained.each_mut().map(|c| {
        (0..3)
            .map(|_| c.train(&q, &t, 2, 1024))
            .collect::<Vec<f64>>()
    });
    let moved = |c: &CacheTrainer| update(&c.cache(), &start).flat();
    let error = relative_error(&moved(&trained[1]), &moved(&trained[0]));
    eprintln!(
        "losses CPU {:?}, GPU {:?}; the updates {error:.1e} apart",
        losses[0], losses[1]
    );
    for (a, b) in losses[0].iter().zip(&losses[1]) {
        assert!((a - b).abs() < 1e-4 * a.abs(), "losses {losses:?}");
    }
    // Adam's update m/√v magnifies the gradients' rounding where they are near zero.
    assert!(error < 1e-3, "the engines' updates {error} apart");
}
