//! The per-epoch validation loss of a Neural PRT network on held-out lighting.

use burn::tensor::Device;

use crate::batch::Batch;
use crate::data::{TrainingSet, ViewSamples};
use crate::design::NprtNet;
use crate::loss::log_l1;

/// Mean log-L1 loss over a fixed, evenly strided subset of at most `max_samples` of the test
/// views' pixels, in batches of `batch_size`; NaN without test pixels.
pub fn validation_loss(
    net: &NprtNet,
    set: &TrainingSet,
    max_samples: usize,
    batch_size: usize,
    device: &Device,
) -> f64 {
    let views: Vec<&ViewSamples> = set.test.iter().filter(|v| !v.is_empty()).collect();
    let total: usize = views.iter().map(|v| v.len()).sum();
    if total == 0 {
        return f64::NAN;
    }
    let stride = total.div_ceil(max_samples.max(1));
    let picked: Vec<(u32, u32)> = views
        .iter()
        .enumerate()
        .flat_map(|(v, view)| (0..view.len() as u32).map(move |p| (v as u32, p)))
        .step_by(stride)
        .collect();
    let mut sum = 0.0;
    for chunk in picked.chunks(batch_size.max(1)) {
        // Only the views this chunk touches go through the encoder.
        let mut used: Vec<u32> = chunk.iter().map(|s| s.0).collect();
        used.dedup();
        let local: Vec<(u32, u32)> = chunk
            .iter()
            .map(|&(v, p)| (used.partition_point(|&u| u < v) as u32, p))
            .collect();
        let sub: Vec<&ViewSamples> = used.iter().map(|&v| views[v as usize]).collect();
        let (pred, reference) = Batch::gather(&sub, &local).forward(net, device);
        sum += log_l1(pred, reference).into_scalar::<f32>() as f64 * chunk.len() as f64;
    }
    sum / picked.len() as f64
}
