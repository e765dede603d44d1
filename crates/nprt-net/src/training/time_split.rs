//! Where a training run's wall time went, for its report.

/// Where a run's wall time went, seconds: the steps (gradients and the optimiser, until the
/// loss is back on the host), waiting for the next batch, validation, and saving (checkpoint,
/// model files, loss curves).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TimeSplit {
    pub steps: f64,
    pub batch_wait: f64,
    pub validation: f64,
    pub saving: f64,
}

impl TimeSplit {
    /// "steps 96.1%, waiting for batches 0.2%, validation 2.5%, saving 1.2% of 12.3 s".
    pub fn describe(&self) -> String {
        let total = self.steps + self.batch_wait + self.validation + self.saving;
        let pct = |t: f64| 100.0 * t / total.max(1e-12);
        format!(
            "steps {:.1}%, waiting for batches {:.1}%, validation {:.1}%, saving {:.1}% of {total:.1} s",
            pct(self.steps),
            pct(self.batch_wait),
            pct(self.validation),
            pct(self.saving)
        )
    }
}
