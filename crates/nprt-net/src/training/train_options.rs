//! The options of a Neural PRT training run (`nprt train`): the loop's schedule and how pixels
//! are batched and validated.

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};

use crate::choice::named_choice;
use crate::loss::Loss;
use crate::network::design::Design;
use crate::precision::Precision;
use crate::training::batch::Batch;
use crate::training::calibration::Calibration;
use crate::training::lr_schedule::LrSchedule;
use crate::training::run_length::RunLength;
use crate::training::schedule::Schedule;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainOptions {
    #[serde(flatten)]
    pub schedule: Schedule,
    pub batch_size: usize,
    /// Views whose pixels are mixed in one batch.
    pub views_per_batch: usize,
    /// Test-view pixels used for the per-epoch validation loss.
    pub val_samples: usize,
    /// What training minimises (validation is always the paper's log-L1).
    #[serde(default)]
    pub loss: Loss,
    /// Whether the saved model's radiance is calibrated to its training targets' level; it
    /// leaves training itself alone, so it is not part of the run's key.
    #[serde(default)]
    pub calibration: Calibration,
    /// Where the batches of steps on our own GPU kernels are gathered; the same batches
    /// either way, so not part of the run's key.
    #[serde(default)]
    pub gather: Gather,
    /// The transport networks' products on our own GPU kernels: f32, or f16 operands summed in
    /// f32 on tensor cores where the adapter has them, with f32 master weights.
    #[serde(default)]
    pub precision: Precision,
    /// What the network is trained to predict: each pixel's radiance under its view's
    /// lighting, or (the linear design on an SH basis) its transfer vector.
    #[serde(default)]
    pub targets: Targets,
}

/// What a training sample's target is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Targets {
    /// The radiance under the view's lighting (the paper's).
    #[default]
    Radiance,
    /// The transfer vector `nprt generate --transfer` recorded: the linear design's
    /// coefficients, for every lighting at once, by their mean squared error.
    Transfer,
}

named_choice!(Targets, "targets", {
    Radiance => "radiance",
    Transfer => "transfer",
});

/// Where a GPU step's batches are gathered.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Gather {
    /// The dataset is uploaded once and each step gathers its batch there from the picks.
    #[default]
    Device,
    /// Batches are gathered on the host and uploaded each step (for datasets the device has no
    /// room for).
    Host,
}

named_choice!(Gather, "gather", {
    Device => "device",
    Host => "host",
});

impl Default for TrainOptions {
    fn default() -> Self {
        TrainOptions {
            schedule: Schedule {
                learning_rate: recipe_rate(Design::Dsep, LrSchedule::Cosine),
                lr_schedule: LrSchedule::Cosine,
                ..Schedule::default()
            },
            batch_size: 16_384,
            views_per_batch: 8,
            val_samples: 65_536,
            loss: Loss::LogL1,
            calibration: Calibration::None,
            gather: Gather::Device,
            precision: Precision::F32,
            targets: Targets::Radiance,
        }
    }
}

/// The default peak learning rate of `design` under `schedule`. Measured on demo-sized data at
/// equal time with the release build (docs/model.md): with warm-up and cosine decay, 5e-4 for
/// the SIREN designs (1e-3 led at a third of the steps, lost at the release build's; PRT
/// once collapsed at 1e-3, its output zero under held-out lighting), 3e-4 for the baseline,
/// whose deep ReLU stack collapses to a constant at 1e-3. The paper's constant schedule keeps
/// the paper's 1e-4.
pub fn recipe_rate(design: Design, schedule: LrSchedule) -> f64 {
    match schedule {
        LrSchedule::Paper => 1e-4,
        LrSchedule::Cosine => design.spec().cosine_rate,
    }
}

impl TrainOptions {
    /// These options run for `run`, at the peak learning rate `lr`, or else the measured
    /// recipe's for `design` under the run's schedule ([`recipe_rate`]).
    pub fn with_run(self, design: Design, run: RunLength, lr: Option<f64>) -> Self {
        let schedule = run.apply(self.schedule);
        TrainOptions {
            schedule: Schedule {
                learning_rate: lr.unwrap_or_else(|| recipe_rate(design, schedule.lr_schedule)),
                ..schedule
            },
            ..self
        }
    }

    /// Refuses settings no run can use.
    pub fn check(&self) -> Result<()> {
        self.schedule.check()?;
        Batch::check_size(self.batch_size, self.views_per_batch, 0)?;
        if self.val_samples == 0 {
            bail!(
                "the validation samples must be positive: every epoch ends with a validation loss"
            );
        }
        Ok(())
    }
}
