//! The divergence stop of the training loop: a loss that is not finite, or a running mean far
//! above its best, ends the run.

/// Stops a run whose loss is not finite or whose running mean rose ten times above its best
/// (measured after 200 steps, once the start's transient is over).
pub(crate) struct DivergenceGuard {
    pub(crate) ema: f64,
    best: f64,
}

impl Default for DivergenceGuard {
    fn default() -> Self {
        DivergenceGuard {
            ema: f64::NAN,
            best: f64::INFINITY,
        }
    }
}

impl DivergenceGuard {
    /// Takes the loss of step `step`; says why the run diverged, if it did.
    pub(crate) fn check(&mut self, loss: f64, step: u64) -> Option<String> {
        self.ema = if self.ema.is_nan() {
            loss
        } else {
            0.98 * self.ema + 0.02 * loss
        };
        if step > 200 {
            self.best = self.best.min(self.ema);
        }
        (!loss.is_finite() || self.ema > 10.0 * self.best).then(|| {
            format!(
                "loss {loss}, running mean {:.4}, best {:.4}",
                self.ema, self.best
            )
        })
    }
}
