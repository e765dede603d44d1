//! Training throughput of a design on synthetic data, for `nprt bench train`.

use std::time::Instant;

use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::Device;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

use crate::batch::Batch;
use crate::features::FEATURES;
use crate::init::Init;
use crate::loss::log_l1;
use crate::model::ModelConfig;
use crate::trainer::ADAM_EPSILON;

/// Samples/s of `steps` full steps (forward, backward, Adam) on one synthetic batch of
/// `batch_size` samples over `views` maps, after `warmup` untimed steps.
pub fn measure_throughput(
    config: &ModelConfig,
    batch_size: usize,
    views: usize,
    steps: usize,
    warmup: usize,
    device: &Device,
) -> f64 {
    let device = device.clone().autodiff();
    let mut net = config.build(&mut Init::new(0, &device));
    let mut optim = AdamConfig::new().with_epsilon(ADAM_EPSILON).init();
    let mut rng = Pcg64Mcg::seed_from_u64(0);
    let w = config.encoder_width;
    let mut random = |n: usize, scale: f32| -> Vec<f32> {
        (0..n).map(|_| rng.random::<f32>() * scale).collect()
    };
    let batch = Batch {
        features: random(batch_size * FEATURES, 1.0),
        radiance: random(batch_size * 3, 4.0),
        view: (0..batch_size).map(|i| (i % views) as i64).collect(),
        scale: random(batch_size, 1.0)
            .into_iter()
            .map(|s| s + 0.5)
            .collect(),
        lights: random(views * 3 * w * w / 2, 1.0),
        light_width: w,
    };
    let mut timed = Instant::now();
    for step in 0..warmup + steps {
        if step == warmup {
            device.sync().ok();
            timed = Instant::now();
        }
        let (pred, reference) = batch.forward(&net, &device);
        let grads = GradientsParams::from_grads(log_l1(pred, reference).backward(), &net);
        net = optim.step(1e-4, net, grads);
    }
    device.sync().ok();
    (batch_size * steps) as f64 / timed.elapsed().as_secs_f64()
}
