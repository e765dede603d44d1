//! The training loop's own settings, shared by every network: epochs, learning rate and its
//! schedule, time budget, seed and checkpoint interval.

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};

use crate::training::lr_schedule::LrSchedule;
use crate::training::minutes::check_minutes;
use crate::training::snapshot::Snapshot;

/// The loop's own settings, shared by every network.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Schedule {
    /// Passes over the data; with a time budget, the most the run may do.
    pub epochs: usize,
    /// The peak learning rate.
    pub learning_rate: f64,
    /// How the rate moves over the run (the paper: constant).
    #[serde(default)]
    pub lr_schedule: LrSchedule,
    /// Wall-clock budget of training time, minutes: the run stops when its accumulated time
    /// reaches it (or after `epochs`, whichever comes first), and a decaying schedule decays
    /// over it instead of over the epochs.
    #[serde(default)]
    pub minutes: Option<f64>,
    /// Seed of the initial weights and of the batch order.
    pub seed: u64,
    /// Seconds between checkpoints inside an epoch; an epoch's end writes one once this many
    /// seconds or 10 have passed since the last, and the run's end always does.
    #[serde(skip)]
    pub checkpoint_secs: f64,
    #[serde(skip)]
    pub progress: bool,
    /// Points at which the run keeps its model (`--snapshots`); they change nothing of the run
    /// itself, so a run resumes with other ones.
    #[serde(skip)]
    pub snapshots: Vec<Snapshot>,
    /// Minutes of training after which this call stops, saved, wherever the run stands
    /// (`--pause-after`): a long run advanced a loan at a time. Not part of the run, which the
    /// same call continues.
    #[serde(skip)]
    pub pause_after: Option<f64>,
}

impl Default for Schedule {
    /// The paper's learning rate; a checkpoint every 5 minutes within an epoch.
    fn default() -> Self {
        Schedule {
            epochs: 20,
            learning_rate: 1e-4,
            lr_schedule: LrSchedule::Paper,
            minutes: None,
            seed: 0,
            checkpoint_secs: 300.0,
            progress: true,
            snapshots: Vec::new(),
            pause_after: None,
        }
    }
}

impl Schedule {
    /// Refuses settings no run can use.
    pub fn check(&self) -> Result<()> {
        if self.epochs == 0 {
            bail!("the number of epochs must be positive");
        }
        if !(self.learning_rate > 0.0 && self.learning_rate.is_finite()) {
            bail!(
                "the learning rate must be a positive number, got {}",
                self.learning_rate
            );
        }
        if let Some(m) = self.minutes {
            check_minutes(m, "the time budget (--minutes)").map_err(anyhow::Error::msg)?;
        }
        if let Some(m) = self.pause_after {
            check_minutes(m, "the pause (--pause-after)").map_err(anyhow::Error::msg)?;
        }
        Ok(())
    }

    /// The budget in seconds, if the run has one.
    pub(crate) fn budget_secs(&self) -> Option<f64> {
        self.minutes.map(|m| m * 60.0)
    }

    /// This call's training before it pauses, in seconds, if it pauses.
    pub(crate) fn pause_secs(&self) -> Option<f64> {
        self.pause_after.map(|m| m * 60.0)
    }

    /// "epoch 3/20", or "epoch 3" for a run bounded by its time budget alone.
    pub(crate) fn epoch_label(&self, epoch: usize) -> String {
        if self.epochs == usize::MAX {
            format!("epoch {epoch}")
        } else {
            format!("epoch {epoch}/{}", self.epochs)
        }
    }
}
