//! What one network's training is, as the one training loop takes it ([`Objective`]), and
//! what a run reports when it ends ([`TrainSummary`]).

use std::path::Path;

use anyhow::Result;

use crate::init::Init;
use crate::optimiser::EngineSteps;
use crate::parameters::Parameters;
use crate::training::checkpoint::RunState;
use crate::training::live::LiveRun;
use crate::training::schedule::Schedule;
use crate::training::time_split::TimeSplit;

/// The steps of an objective's engine, borrowing the objective.
pub type Steps<'a, O> = Box<dyn EngineSteps<<O as Objective>::Net, <O as Objective>::Batch> + 'a>;

/// What one network's training is: its construction, its batches, its loss and the engine that
/// takes its steps.
pub trait Objective: Sync {
    type Net: Parameters + Clone;
    /// Built on the batch thread, taken by the training thread.
    type Batch: Send;
    /// Names the network in its weights' metadata and in messages.
    fn tag(&self) -> String;
    /// Title of the loss plot.
    fn title(&self) -> String;
    /// All that shapes the run besides the schedule (network, data, batching): a checkpoint
    /// resumes only under an equal key.
    fn run_key(&self) -> serde_json::Value;
    fn build(&self, init: &mut Init) -> Self::Net;
    /// Batches in `epoch`.
    fn steps(&self, seed: u64, epoch: usize) -> usize;
    /// The batches of `epoch` from index `from` on; a function of `seed` and `epoch` only.
    fn batches(
        &self,
        seed: u64,
        epoch: usize,
        from: usize,
    ) -> impl Iterator<Item = Self::Batch> + '_;
    /// The engine's steps from `net` (its weights as they stand) with fresh moments.
    fn engine_steps(&self, net: &Self::Net) -> Result<Steps<'_, Self>>;
    /// Loss on held-out data under the parameters `steps` hold; NaN where there is no
    /// held-out data.
    fn validation_loss(&self, steps: &mut dyn EngineSteps<Self::Net, Self::Batch>) -> Result<f64>;
    /// The model folder's own files (config and weights), which a diverged run removes.
    fn model_files(&self) -> [&'static str; 2];
    /// Checks that the data the run reads is still what it was when the run began (a pack
    /// written over during the run): asked when a run diverges and before its last save.
    fn check_data(&self) -> Result<()> {
        Ok(())
    }
    /// Writes the model folder's own files (config and weights) for the network as it stands.
    fn save_model(
        &self,
        out: &Path,
        net: &Self::Net,
        schedule: &Schedule,
        state: &RunState,
    ) -> Result<()>;
    /// Hands a live run's watcher the model as it stands (as [`Self::save_model`] would write
    /// it); networks no watcher can show publish nothing.
    fn publish(&self, _net: &Self::Net, _schedule: &Schedule, _state: &RunState, _live: &LiveRun) {}
}

/// What a finished (or resumed and finished) run reports.
pub struct TrainSummary {
    /// Epochs done, counting a part-done one by its share of batches.
    pub epochs: f64,
    pub steps: u64,
    pub samples: u64,
    pub seconds: f64,
    pub final_train: f64,
    pub final_val: f64,
    pub resumed_from_epoch: Option<f64>,
    /// This call stopped at its `pause_after` with the run unfinished.
    pub paused: bool,
    /// Where the steps ran: "cpu", or "GPU kernels on …".
    pub steps_on: String,
    /// Where this invocation's time went.
    pub split: TimeSplit,
}
