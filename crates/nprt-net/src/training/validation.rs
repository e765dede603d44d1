//! The per-epoch validation loss of a Neural PRT network on held-out lighting.

use anyhow::Result;

use crate::training::batch::Batch;
use crate::training::training_set::{TrainingSet, ViewSamples};

/// Mean log-L1 loss over a fixed, evenly strided subset of at most `max_samples` of the test
/// views' pixels, in batches of `batch_size`, each batch's mean by `batch_loss`; NaN without
/// test pixels.
pub fn validation_loss(
    set: &TrainingSet,
    max_samples: usize,
    batch_size: usize,
    mut batch_loss: impl FnMut(&Batch) -> Result<f64>,
) -> Result<f64> {
    let views: Vec<&ViewSamples> = set.test.iter().filter(|v| !v.is_empty()).collect();
    let (mut sum, mut count) = (0.0, 0);
    for batch in Batch::strided(&views, max_samples, batch_size) {
        sum += batch_loss(&batch)? * batch.len() as f64;
        count += batch.len();
    }
    views.iter().for_each(|v| v.release());
    if count == 0 {
        return Ok(f64::NAN);
    }
    Ok(sum / count as f64)
}
