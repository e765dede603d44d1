//! Training throughput and inference speed of a design on synthetic data, for `nprt bench`.

use std::time::Instant;

use burn::optim::AdamConfig;
use burn::tensor::{Device, Tensor, TensorData};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

use crate::encoding::features::FEATURES;
use crate::model::config::ModelConfig;
use crate::network::encoder::CODE_SIZE;
use crate::network::init::Init;
use crate::training::batch::{Batch, Engine};
use crate::training::loss::Loss;
use crate::training::training_loop::ADAM_EPSILON;
use crate::Precision;

/// Samples/s of `steps` full steps (forward, backward, Adam) on one synthetic batch of
/// `batch_size` samples over `views` maps, after `warmup` untimed steps, gradients computed by
/// `engine`; on our own GPU kernels (wgpu) in `precision` (elsewhere f32 only).
#[allow(clippy::too_many_arguments)]
pub fn measure_throughput(
    config: &ModelConfig,
    engine: Engine,
    batch_size: usize,
    views: usize,
    steps: usize,
    warmup: usize,
    precision: Precision,
    device: &Device,
) -> anyhow::Result<f64> {
    let device = device.clone().autodiff();
    let mut net = config.build(&mut Init::new(0, &device));
    let mut optim = AdamConfig::new().with_epsilon(ADAM_EPSILON).init();
    let batch = synthetic_batch(config, batch_size, views);
    #[cfg(feature = "kernels")]
    if crate::device::Backend::of(&device) == crate::device::Backend::Wgpu {
        return kernel_throughput(config, &batch, steps, warmup, precision);
    }
    anyhow::ensure!(
        precision == Precision::F32,
        "--precision {precision} runs on nprt's own GPU kernels only: use --device wgpu"
    );
    let mut timed = Instant::now();
    for step in 0..warmup + steps {
        if step == warmup {
            device.sync().ok();
            timed = Instant::now();
        }
        let (_, grads) = batch.gradients(&net, &device, engine, Loss::LogL1);
        net = optim.step(1e-4, net, grads);
    }
    device.sync().ok();
    Ok((batch_size * steps) as f64 / timed.elapsed().as_secs_f64())
}

/// A batch of uniform random values (seeded): `batch_size` samples over `views` maps.
fn synthetic_batch(config: &ModelConfig, batch_size: usize, views: usize) -> Batch {
    let mut rng = Pcg64Mcg::seed_from_u64(0);
    let w = config.encoder_width;
    let mut random = |n: usize, scale: f32| -> Vec<f32> {
        (0..n).map(|_| rng.random::<f32>() * scale).collect()
    };
    Batch {
        features: random(batch_size * FEATURES, 1.0),
        radiance: random(batch_size * 3, 4.0),
        view: (0..batch_size).map(|i| (i % views) as i64).collect(),
        scale: random(batch_size * 3, 1.0)
            .into_iter()
            .map(|s| s + 0.5)
            .collect(),
        lights: random(views * 3 * w * w / 2, 1.0),
        light_width: w,
        picks: None,
    }
}

/// The GPU time of each of our kernels in one training step in `precision` on the synthetic
/// batch of [`measure_throughput`], after `warmup` untimed steps (`nprt bench train
/// --profile`).
#[cfg(feature = "kernels")]
pub fn profile_kernels(
    config: &ModelConfig,
    batch_size: usize,
    views: usize,
    warmup: usize,
    precision: Precision,
) -> anyhow::Result<Vec<crate::gpu::KernelTime>> {
    let net = config.build(&mut Init::new(0, &Device::flex()));
    let mut gpu = crate::gpu::GpuTrainer::new(&net, precision)?;
    let batch = synthetic_batch(config, batch_size, views);
    let samples = batch.samples();
    for _ in 0..warmup {
        gpu.queue_step(&samples, Loss::LogL1, 1e-4);
    }
    gpu.profile_step(&samples, Loss::LogL1, 1e-4)
}

/// [`measure_throughput`] on our own GPU kernels (what `--device wgpu` trains with): each step
/// reads the loss of the one before it back while it runs, as a training run does.
#[cfg(feature = "kernels")]
fn kernel_throughput(
    config: &ModelConfig,
    batch: &Batch,
    steps: usize,
    warmup: usize,
    precision: Precision,
) -> anyhow::Result<f64> {
    let net = config.build(&mut Init::new(0, &Device::flex()));
    let mut gpu = crate::gpu::GpuTrainer::new(&net, precision)?;
    let samples = batch.samples();
    let mut timed = Instant::now();
    for step in 0..warmup + steps {
        if step == warmup {
            timed = Instant::now();
        }
        gpu.queue_step(&samples, Loss::LogL1, 1e-4);
    }
    gpu.finish();
    Ok((batch.len() * steps) as f64 / timed.elapsed().as_secs_f64())
}

/// The median of timings (the upper one of an even count): what benchmarks report, since a
/// shared machine's speed drifts from run to run.
pub fn median(mut v: Vec<f64>) -> f64 {
    assert!(!v.is_empty(), "median of no timings");
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Inference speed of a design's transport networks.
pub struct InferenceSpeed {
    pub pixels: usize,
    /// A frame from a new viewpoint: transfer and shading networks.
    pub frame_ms: f64,
    /// A lighting change under a still camera: shading networks only (the transfer networks'
    /// outputs kept); equal to `frame_ms` for the baseline, which has none, and off the CPU,
    /// where the outputs are not kept.
    pub relight_ms: f64,
    pub frame_gflops: f64,
    pub relight_gflops: f64,
}

/// Median over `repeats` runs of the transport networks on `pixels` synthetic foreground
/// pixels on `device` (the encoder, once per lighting, is not counted). On the CPU the engine
/// runs from host memory; elsewhere the features stay on the device and the timed work ends
/// with the frame's radiance read back.
pub fn measure_inference(
    config: &ModelConfig,
    pixels: usize,
    repeats: usize,
    device: &Device,
) -> InferenceSpeed {
    let net = config.build(&mut Init::new(0, device));
    let host = crate::cpu::HostTransport::from_net(&net);
    let mut rng = Pcg64Mcg::seed_from_u64(1);
    let features: Vec<f32> = (0..pixels * FEATURES)
        .map(|_| rng.random::<f32>())
        .collect();
    let code: Vec<f32> = (0..CODE_SIZE).map(|_| rng.random::<f32>() - 0.5).collect();
    let median_ms = |run: &dyn Fn()| {
        run();
        median(
            (0..repeats.max(1))
                .map(|_| {
                    let t = Instant::now();
                    run();
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect(),
        )
    };
    let (frame_ms, relight_ms, kept) = if crate::device::is_cpu(device) {
        let kept = host.transfer_codes(&features);
        let frame = median_ms(&|| {
            host.radiance(&features, &code, [1.0; 3], None);
        });
        let relight = median_ms(&|| {
            host.radiance(&features, &code, [1.0; 3], Some(&kept));
        });
        (frame, relight, true)
    } else {
        let f = Tensor::<2>::from_data(TensorData::new(features, [pixels, FEATURES]), device);
        let code = Tensor::<2>::from_data(TensorData::new(code, [1, CODE_SIZE]), device)
            .expand([pixels, CODE_SIZE]);
        let scale = Tensor::<2>::ones([pixels, 1], device);
        let frame = median_ms(&|| {
            // The frame is read back whole, as a renderer does: a partial read let the
            // backend skip work (measured: "400 TFLOP/s" on an H100).
            net.shade(f.clone(), code.clone(), scale.clone())
                .into_data();
        });
        (frame, frame, false)
    };
    let gflops = |flops: f64, ms: f64| flops * pixels as f64 / (ms * 1e6);
    InferenceSpeed {
        pixels,
        frame_ms,
        relight_ms,
        frame_gflops: gflops(host.flops_per_pixel(false), frame_ms),
        relight_gflops: gflops(host.flops_per_pixel(kept), relight_ms),
    }
}
