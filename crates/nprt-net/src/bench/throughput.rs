//! Training throughput and inference speed of a design on synthetic data, for `nprt bench`.

use std::time::Instant;

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

use crate::encoding::features::FEATURES;
use crate::engine::Engine;
use crate::init::Init;
use crate::loss::Loss;
use crate::model::config::ModelConfig;
use crate::optimiser::Adam;
use crate::parameters::Parameters;
use crate::precision::Precision;
use crate::training::batch::Batch;

/// Samples/s of `steps` full steps (forward, backward, Adam) on one synthetic batch of
/// `batch_size` samples over `views` maps, after `warmup` untimed steps: on the CPU engine, or
/// on the GPU kernels in `precision` (elsewhere f32 only).
#[allow(clippy::too_many_arguments)]
// Without the kernels `engine` is always the CPU.
#[cfg_attr(not(feature = "gpu"), allow(unused_variables))]
pub fn measure_throughput(
    config: &ModelConfig,
    batch_size: usize,
    views: usize,
    steps: usize,
    warmup: usize,
    precision: Precision,
    engine: Engine,
) -> anyhow::Result<f64> {
    let batch = synthetic_batch(config, batch_size, views)?;
    #[cfg(feature = "gpu")]
    if engine.is_gpu() {
        return kernel_throughput(config, &batch, steps, warmup, precision);
    }
    anyhow::ensure!(
        precision == Precision::F32,
        "--precision {precision} runs on nprt's own GPU kernels only: use --device gpu"
    );
    let mut net = config.build(&mut Init::new(0));
    let mut adam = Adam::new(net.num_params());
    let mut timed = Instant::now();
    for step in 0..warmup + steps {
        if step == warmup {
            timed = Instant::now();
        }
        let (_, grads) = crate::cpu::gradients(&net, &batch.samples(), Loss::LogL1);
        adam.step(&mut net, &grads, 1e-4);
    }
    Ok((batch_size * steps) as f64 / timed.elapsed().as_secs_f64())
}

/// A batch of uniform random values (seeded): `batch_size` samples over `views` maps, refused
/// where the machine cannot hold it.
fn synthetic_batch(config: &ModelConfig, batch_size: usize, views: usize) -> anyhow::Result<Batch> {
    Batch::check_size(batch_size, views, config.encoder_width)?;
    let mut rng = Pcg64Mcg::seed_from_u64(0);
    let w = config.encoder_width;
    let mut random = |n: usize, scale: f32| -> Vec<f32> {
        (0..n).map(|_| rng.random::<f32>() * scale).collect()
    };
    Ok(Batch {
        features: random(batch_size * FEATURES, 1.0),
        radiance: random(batch_size * 3, 4.0),
        transfer: Vec::new(),
        view: (0..batch_size).map(|i| (i % views) as i64).collect(),
        scale: random(batch_size * 3, 1.0)
            .into_iter()
            .map(|s| s + 0.5)
            .collect(),
        lights: random(views * 3 * w * w / 2, 1.0),
        light_width: w,
        picks: None,
    })
}

/// The GPU time of each of our kernels in one training step in `precision` on the synthetic
/// batch of [`measure_throughput`], after `warmup` untimed steps (`nprt bench train
/// --profile`).
#[cfg(feature = "gpu")]
pub fn profile_kernels(
    config: &ModelConfig,
    batch_size: usize,
    views: usize,
    warmup: usize,
    precision: Precision,
) -> anyhow::Result<Vec<nprt_gpu::KernelTime>> {
    let net = config.build(&mut Init::new(0));
    let mut gpu = crate::gpu::GpuTrainer::new(&net, precision)?;
    let batch = synthetic_batch(config, batch_size, views)?;
    let samples = batch.samples();
    for _ in 0..warmup {
        gpu.queue_step(&samples, Loss::LogL1, 1e-4);
    }
    gpu.profile_step(&samples, Loss::LogL1, 1e-4)
}

/// [`measure_throughput`] on our own GPU kernels (what `--device gpu` trains with): each step
/// reads the loss of the one before it back while it runs, as a training run does.
#[cfg(feature = "gpu")]
fn kernel_throughput(
    config: &ModelConfig,
    batch: &Batch,
    steps: usize,
    warmup: usize,
    precision: Precision,
) -> anyhow::Result<f64> {
    let net = config.build(&mut Init::new(0));
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
    /// A lighting change under a still camera: what runs from where the light enters on (the
    /// shading networks after the kept ŝ, a linear design's dot products after its kept
    /// transfer coefficients); equal to `frame_ms` for the baseline, which keeps nothing.
    pub relight_ms: f64,
    pub frame_gflops: f64,
    pub relight_gflops: f64,
}

/// Median over `repeats` runs of the CPU engine's transport networks on `pixels` synthetic
/// foreground pixels in host memory (the encoder, once per lighting, is not counted). The GPU
/// kernels' frames are timed by nprt-render's `bench frame`, which keeps them on the device.
pub fn measure_inference(config: &ModelConfig, pixels: usize, repeats: usize) -> InferenceSpeed {
    let net = config.build(&mut Init::new(0));
    let host = &net;
    let mut rng = Pcg64Mcg::seed_from_u64(1);
    let features: Vec<f32> = (0..pixels * FEATURES)
        .map(|_| rng.random::<f32>())
        .collect();
    // The light model's code: the encoder's ê, or a linear design's projection on its basis.
    let code_size = net.light.code_size();
    let code: Vec<f32> = (0..code_size).map(|_| rng.random::<f32>() - 0.5).collect();
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
    let kept = host.kept_rows(&features);
    let frame_ms = median_ms(&|| {
        host.radiance(&features, &code, [1.0; 3], None);
    });
    let relight_ms = median_ms(&|| {
        host.radiance(&features, &code, [1.0; 3], Some(&kept));
    });
    let gflops = |flops: f64, ms: f64| flops * pixels as f64 / (ms * 1e6);
    InferenceSpeed {
        pixels,
        frame_ms,
        relight_ms,
        frame_gflops: gflops(host.flops_per_pixel(false), frame_ms),
        relight_gflops: gflops(host.flops_per_pixel(true), relight_ms),
    }
}
