//! The options of a Neural PRT training run (`nprt train`): the loop's schedule and how pixels
//! are batched and validated.

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};

use crate::trainer::Schedule;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainOptions {
    #[serde(flatten)]
    pub schedule: Schedule,
    pub batch_size: usize,
    /// Views whose pixels are mixed in one batch.
    pub views_per_batch: usize,
    /// Test-view pixels used for the per-epoch validation loss.
    pub val_samples: usize,
}

impl Default for TrainOptions {
    fn default() -> Self {
        TrainOptions {
            schedule: Schedule::default(),
            batch_size: 16_384,
            views_per_batch: 8,
            val_samples: 65_536,
        }
    }
}

impl TrainOptions {
    /// Refuses settings no run can use.
    pub fn check(&self) -> Result<()> {
        self.schedule.check()?;
        if self.batch_size == 0 || self.views_per_batch == 0 {
            bail!("the batch size and the views per batch must be positive");
        }
        Ok(())
    }
}
