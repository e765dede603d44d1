//! The training losses: the paper's L1 distance between log(1 + x) of predicted and reference
//! radiance, and a relative L2 whose minimiser on noisy targets is their mean. One definition
//! serves training on every engine (the GPU kernels restate it and are tested against it),
//! validation and the log-L1 metric.

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
    /// The mean loss of `prediction` against `reference` (as many values each).
    pub fn mean(self, prediction: &[f32], reference: &[f32]) -> f64 {
        let sum: f64 = (prediction.iter().zip(reference))
            .map(|(&p, &r)| self.element(p, r).0 as f64)
            .sum();
        sum / prediction.len().max(1) as f64
    }

    /// One element's loss and its derivative in the prediction `p`.
    pub fn element(self, p: f32, r: f32) -> (f32, f32) {
        match self {
            Loss::LogL1 => {
                let (log_p, slope) = log_1p_extended(p);
                let d = log_p - r.ln_1p();
                let sign = if d > 0.0 {
                    1.0
                } else if d < 0.0 {
                    -1.0
                } else {
                    0.0
                };
                (d.abs(), sign * slope)
            }
            Loss::RelL2 => {
                let (d, w) = (p - r, 1.0 / (p * p + RELATIVE_L2_EPS));
                (d * d * w, 2.0 * d * w)
            }
        }
    }
}

/// log(1 + p) and its derivative, continued below 0 by its tangent there (p itself, slope 1):
/// the linear design's radiance is a dot product that can be negative while it learns, where
/// log(1 + p) is undefined below −1 and its gradient would grow without bound; the designs
/// whose radiance is an exp never reach it.
fn log_1p_extended(p: f32) -> (f32, f32) {
    if p >= 0.0 {
        (p.ln_1p(), 1.0 / (1.0 + p))
    } else {
        (p, 1.0)
    }
}

/// One value's log-L1 error, for metrics on images. Negative radiance (a denoiser's overshoot)
/// counts as zero, where log(1 + x) is defined.
pub fn log_l1_error(prediction: f64, reference: f64) -> f64 {
    (prediction.max(0.0).ln_1p() - reference.max(0.0).ln_1p()).abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Below zero the loss goes on as its tangent at zero: finite, and pulling the prediction
    /// up with slope −1.
    #[test]
    fn log_l1_is_defined_and_pulls_up_below_zero() {
        assert_eq!(Loss::LogL1.element(-3.0, 1.0), (3.0 + 2f32.ln(), -1.0));
        let (at_zero, slope) = Loss::LogL1.element(0.0, 1.0);
        assert_eq!((at_zero, slope), (2f32.ln(), -1.0));
        let (above, _) = Loss::LogL1.element(1.0, 1.0);
        assert_eq!(above, 0.0);
    }
}
