//! How long a training run lasts and how its learning rate moves, as a user asks for it: each
//! part left unset keeps the run's default.

use crate::training::lr_schedule::LrSchedule;
use crate::training::schedule::Schedule;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RunLength {
    /// Passes over the training data.
    pub epochs: Option<usize>,
    /// Wall-clock budget of training time; without `epochs` the run is bounded by it alone.
    pub minutes: Option<f64>,
    pub lr_schedule: Option<LrSchedule>,
}

impl RunLength {
    /// A budget of wall-clock minutes: what a faster machine gets is a better model.
    pub const fn minutes(m: f64) -> Self {
        RunLength {
            epochs: None,
            minutes: Some(m),
            lr_schedule: None,
        }
    }

    /// A fixed number of epochs, for a reproducible run.
    pub const fn epochs(e: usize) -> Self {
        RunLength {
            epochs: Some(e),
            minutes: None,
            lr_schedule: None,
        }
    }

    /// `defaults` with this run's length and schedule.
    pub fn apply(self, defaults: Schedule) -> Schedule {
        let epochs = match (self.epochs, self.minutes) {
            (Some(e), _) => e,
            (None, Some(_)) => usize::MAX,
            (None, None) => defaults.epochs,
        };
        Schedule {
            epochs,
            minutes: self.minutes,
            lr_schedule: self.lr_schedule.unwrap_or(defaults.lr_schedule),
            ..defaults
        }
    }
}
