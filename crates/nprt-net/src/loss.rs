//! The paper's loss: L1 distance between log(1 + x) of predicted and reference radiance. One
//! definition serves training (every network, Deep Shading included) and the log-L1 metric.

use burn::tensor::Tensor;

/// Per-element |log(1 + p) − log(1 + r)|, any tensor rank.
pub fn log_l1_map<const D: usize>(prediction: Tensor<D>, reference: Tensor<D>) -> Tensor<D> {
    (prediction.log1p() - reference.log1p()).abs()
}

/// The mean of [`log_l1_map`]: the training loss of the Neural PRT designs.
pub fn log_l1<const D: usize>(prediction: Tensor<D>, reference: Tensor<D>) -> Tensor<1> {
    log_l1_map(prediction, reference).mean()
}

/// One value's log-L1 error, for metrics on images. Negative radiance (a denoiser's overshoot)
/// counts as zero, where log(1 + x) is defined.
pub fn log_l1_error(prediction: f64, reference: f64) -> f64 {
    (prediction.max(0.0).ln_1p() - reference.max(0.0).ln_1p()).abs()
}
