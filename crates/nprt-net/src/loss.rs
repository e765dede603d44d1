//! The training losses: the paper's L1 distance between log(1 + x) of predicted and reference
//! radiance, and a relative L2 whose minimiser on noisy targets is their mean. One definition
//! serves training (burn and the CPU engine), validation and the log-L1 metric.

use burn::tensor::Tensor;

use crate::choice::named_choice;

/// ε of the relative L2 loss (the report's relative metrics use the same).
pub const RELATIVE_L2_EPS: f32 = 0.01;

/// What the Neural PRT designs are trained to minimise.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Loss {
    /// The paper's: mean |log(1 + p) − log(1 + r)|. On noisy targets it is minimised by their
    /// median, below their mean for path-traced radiance.
    #[default]
    LogL1,
    /// mean (p − r)² / (p̄² + ε) with p̄ the prediction held constant (Lehtinen et al. 2018,
    /// Noise2Noise): on noisy targets its expected gradient vanishes at their mean.
    RelL2,
}

named_choice!(Loss, "loss", {
    LogL1 => "log-l1",
    RelL2 => "rel-l2",
});

impl Loss {
    /// The mean loss of `prediction` against `reference` ([B, 3]), differentiable.
    pub fn mean(self, prediction: Tensor<2>, reference: Tensor<2>) -> Tensor<1> {
        match self {
            Loss::LogL1 => log_l1(prediction, reference),
            Loss::RelL2 => {
                let weight = prediction
                    .clone()
                    .detach()
                    .square()
                    .add_scalar(RELATIVE_L2_EPS);
                ((prediction - reference).square() / weight).mean()
            }
        }
    }

    /// One element's loss and its derivative in the prediction `p` (for the CPU engine).
    pub fn element(self, p: f32, r: f32) -> (f32, f32) {
        match self {
            Loss::LogL1 => {
                let d = p.ln_1p() - r.ln_1p();
                let sign = if d > 0.0 {
                    1.0
                } else if d < 0.0 {
                    -1.0
                } else {
                    0.0
                };
                (d.abs(), sign / (1.0 + p))
            }
            Loss::RelL2 => {
                let (d, w) = (p - r, 1.0 / (p * p + RELATIVE_L2_EPS));
                (d * d * w, 2.0 * d * w)
            }
        }
    }
}

/// Per-element |log(1 + p) − log(1 + r)|, any tensor rank.
pub fn log_l1_map<const D: usize>(prediction: Tensor<D>, reference: Tensor<D>) -> Tensor<D> {
    (prediction.log1p() - reference.log1p()).abs()
}

/// The mean of [`log_l1_map`]: the paper's training loss, and every run's validation loss.
pub fn log_l1<const D: usize>(prediction: Tensor<D>, reference: Tensor<D>) -> Tensor<1> {
    log_l1_map(prediction, reference).mean()
}

/// One value's log-L1 error, for metrics on images. Negative radiance (a denoiser's overshoot)
/// counts as zero, where log(1 + x) is defined.
pub fn log_l1_error(prediction: f64, reference: f64) -> f64 {
    (prediction.max(0.0).ln_1p() - reference.max(0.0).ln_1p()).abs()
}
