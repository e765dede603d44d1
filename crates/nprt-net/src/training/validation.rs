//! The per-epoch validation loss of a Neural PRT network on held-out lighting.

use burn::tensor::Device;

use crate::network::nprt_net::NprtNet;
use crate::training::batch::Batch;
use crate::training::loss::log_l1;
use crate::training::training_set::{TrainingSet, ViewSamples};

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
    let (mut sum, mut count) = (0.0, 0);
    for batch in Batch::strided(&views, max_samples, batch_size) {
        let (pred, reference) = batch.forward(net, device);
        sum += log_l1(pred, reference).into_scalar::<f32>() as f64 * batch.len() as f64;
        count += batch.len();
    }
    views.iter().for_each(|v| v.release());
    if count == 0 {
        return f64::NAN;
    }
    sum / count as f64
}
