//! How the learning rate moves over a run: the paper's constant rate, or a warm-up followed by
//! a cosine decay over the run's length (its epochs, or its wall-clock budget).

use crate::choice::named_choice;

/// Share of the run spent warming up linearly from zero.
const WARMUP: f64 = 0.02;
/// The rate at the end of the decay, as a share of the peak.
const FLOOR: f64 = 0.05;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LrSchedule {
    /// The paper's: the rate as given, throughout.
    #[default]
    Paper,
    /// Linear warm-up over the first 2% of the run, then a cosine decay to 5% of the rate.
    Cosine,
}

named_choice!(LrSchedule, "learning-rate schedule", {
    Paper => "paper",
    Cosine => "cosine",
});

impl LrSchedule {
    /// The rate's multiplier at `progress` ∈ [0, 1] of the run.
    pub fn factor(self, progress: f64) -> f64 {
        let p = progress.clamp(0.0, 1.0);
        match self {
            LrSchedule::Paper => 1.0,
            LrSchedule::Cosine if p < WARMUP => p / WARMUP,
            LrSchedule::Cosine => {
                let t = (p - WARMUP) / (1.0 - WARMUP);
                FLOOR + (1.0 - FLOOR) * 0.5 * (1.0 + (std::f64::consts::PI * t).cos())
            }
        }
    }

    /// Whether the rate depends on the run's length, so that a run cannot be lengthened.
    pub fn needs_horizon(self) -> bool {
        self != LrSchedule::Paper
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_warms_up_peaks_and_decays_to_its_floor() {
        let c = LrSchedule::Cosine;
        assert_eq!(c.factor(0.0), 0.0);
        assert!((c.factor(WARMUP / 2.0) - 0.5).abs() < 1e-12);
        assert!((c.factor(WARMUP) - 1.0).abs() < 1e-12);
        let mid = WARMUP + (1.0 - WARMUP) / 2.0;
        assert!((c.factor(mid) - (1.0 + FLOOR) / 2.0).abs() < 1e-12);
        assert!((c.factor(1.0) - FLOOR).abs() < 1e-12);
        assert!((c.factor(7.0) - FLOOR).abs() < 1e-12);
        let samples: Vec<f64> = (0..=100)
            .map(|i| c.factor(WARMUP + i as f64 / 100.0 * (1.0 - WARMUP)))
            .collect();
        assert!(samples.windows(2).all(|w| w[1] <= w[0]));
        assert_eq!(LrSchedule::Paper.factor(0.0), 1.0);
        assert_eq!(LrSchedule::Paper.factor(0.9), 1.0);
        assert_eq!("cosine".parse::<LrSchedule>().unwrap(), c);
        assert!("linear".parse::<LrSchedule>().is_err());
    }
}
