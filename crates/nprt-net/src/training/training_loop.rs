//! The one training loop, whatever the network: Adam as the paper (ε = 1e-8), checkpoints
//! with the optimiser's moments, exact resume, a divergence stop that keeps the last good
//! checkpoint, per-epoch validation, `loss.csv` and `loss.png`. What is trained, on which
//! batches and with which loss is an [`Objective`]: the Neural PRT designs and the Deep
//! Shading U-Net are two.
//!
//! Resume is exact because a batch is a function of the seed, the epoch and its index only,
//! and a network's tensors (which Adam's state follows) come in one fixed order.
//!
//! Batches are built on a thread of their own, a few ahead of the step that takes them, so
//! that a fast device does not wait for the host to gather its samples; the run reports how
//! its time split between steps, waiting for batches, validation and saving.

use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

use crate::init::Init;
use crate::training::checkpoint::{self, Checkpoint, RunState};
use crate::training::live::LiveRun;
use crate::training::loss_curves::LossRow;
pub use crate::training::objective::{Objective, Steps, TrainSummary};
use crate::training::run::{since, Run};
use crate::training::schedule::Schedule;
pub use crate::training::time_split::TimeSplit;

/// Seconds since the last checkpoint after which an epoch's end writes one (the run's end
/// always does): a small dataset's epochs take a GPU milliseconds, and writing the checkpoint,
/// the model and the plot after each took a quarter of a 30-second run on an H200.
const EPOCH_CHECKPOINT_SECS: f64 = 10.0;

/// The random stream of one part (`stream`) of one epoch: shuffles depend on nothing else.
pub fn epoch_rng(seed: u64, epoch: u64, stream: u64) -> Pcg64Mcg {
    let key = [seed, epoch, stream].map(u64::to_le_bytes).concat();
    let h = blake3::hash(&key);
    let mut first = [0; 8];
    first.copy_from_slice(&h.as_bytes()[..8]);
    Pcg64Mcg::seed_from_u64(u64::from_le_bytes(first))
}

/// Who watches a run. `epoch_end` is told each epoch's end (the row it adds to its loss
/// curves) and says whether to go on: `false` ends the run there, saved as the end of a time
/// budget saves it, so that the same call resumes it later (the command line goes on;
/// Python's `nprt.train` passes its callback's answer and stops on Ctrl-C). `live`, where
/// given, is told where the run stands at every step and handed its model when it wants one,
/// and may pause, save, lengthen or stop it (`nprt view --train`).
#[derive(Clone, Copy)]
pub struct Watch<'a> {
    pub epoch_end: &'a (dyn Fn(&LossRow) -> bool + Sync),
    pub live: Option<&'a LiveRun>,
}

fn go_on(_: &LossRow) -> bool {
    true
}

impl Default for Watch<'_> {
    /// Nobody watches: the run goes to its end.
    fn default() -> Self {
        Watch {
            epoch_end: &go_on,
            live: None,
        }
    }
}

impl<'a> Watch<'a> {
    /// `epoch_end` told each epoch's end.
    pub fn epochs(epoch_end: &'a (dyn Fn(&LossRow) -> bool + Sync)) -> Self {
        Watch {
            epoch_end,
            live: None,
        }
    }

    /// A live run's watcher.
    pub fn live(live: &'a LiveRun) -> Self {
        Watch {
            live: Some(live),
            ..Watch::default()
        }
    }
}

/// Refuses a model folder `out` that is a dataset's: a model goes into a folder of its own.
pub fn check_model_folder(out: &Path) -> Result<()> {
    if out.join(nprt_data::dataset::MANIFEST).exists() {
        bail!(
            "'{}' is a dataset folder (it holds {}); a model goes into a folder of its own \
             (--out)",
            out.display(),
            nprt_data::dataset::MANIFEST
        );
    }
    Ok(())
}

/// Trains (or resumes training of) `objective`'s network in the model folder `out`, telling
/// `watch` each epoch's end.
pub fn train<O: Objective>(
    objective: &O,
    schedule: &Schedule,
    out: &Path,
    watch: Watch,
) -> Result<TrainSummary> {
    schedule.check()?;
    check_model_folder(out)?;
    let mut net = objective.build(&mut Init::new(schedule.seed));
    std::fs::create_dir_all(checkpoint::dir(out))
        .with_context(|| format!("cannot create model folder '{}'", out.display()))?;
    let _lock = nprt_io::lock_folder(out, "model folder", "--out")?;
    let (ck, resumed_from_epoch) = start(objective, schedule, out, &mut net)?;
    let mut steps = objective.engine_steps(&net)?;
    if resumed_from_epoch.is_some() {
        checkpoint::restore_optimiser(out, &ck, steps.as_mut())?;
    }
    let mut run = Run::new(objective, schedule, out, ck, watch.live);
    if let Some(live) = watch.live {
        run.publish(live, &net);
    }
    let (mut trained, mut go_on) = (false, true);
    while go_on && run.ck.state.epoch < schedule.epochs && !run.out_of_time() {
        trained = true;
        let total = run.steps_in(run.ck.state.epoch);
        run.epoch(total, &mut net, steps.as_mut())?;
        steps.store(&mut net);
        // The epoch ended, or the budget ran out within it: validate and save either way.
        let validating = Instant::now();
        let val = objective.validation_loss(steps.as_mut())?;
        run.split.validation += since(validating);
        if !val.is_finite() {
            // The last step's update broke the weights after a finite loss: nothing is saved.
            return Err(run.diverged(&format!("validation loss {val}"), run.ck.state.epoch));
        }
        run.end_epoch(val, total);
        run.take_snapshots(&net)?;
        go_on = (watch.epoch_end)(run.ck.history.last().expect("an epoch's end adds a row"))
            && !run.stopped();
        let finished = !go_on || run.ck.state.epoch >= schedule.epochs || run.out_of_time();
        let since_saved = run.last_checkpoint.elapsed().as_secs_f64();
        if finished {
            if let Err(e) = objective.check_data() {
                return Err(run.abandon(e, run.ck.state.epoch));
            }
        }
        if finished || since_saved >= schedule.checkpoint_secs.min(EPOCH_CHECKPOINT_SECS) {
            run.save(&net, steps.as_ref())?;
        }
    }
    run.bar.finish_and_clear();
    run.steps_on = steps.describe();
    if !trained {
        // A finished run asked again: its model files follow this invocation's options (the
        // output calibration, say), since nothing else will write them.
        objective.save_model(out, &net, &run.schedule, &run.ck.state)?;
    }
    if let Some(live) = watch.live {
        run.report(live);
        run.publish(live, &net);
    }
    Ok(run.summary(resumed_from_epoch))
}

/// The run's checkpoint: the one in `out` (its weights loaded into `net`) or a fresh one, and
/// the epoch it resumes from.
fn start<O: Objective>(
    objective: &O,
    schedule: &Schedule,
    out: &Path,
    net: &mut O::Net,
) -> Result<(Checkpoint, Option<f64>)> {
    let Some(saved) = checkpoint::read(out)? else {
        let fresh = Checkpoint {
            run: run_key(objective, schedule),
            state: RunState::default(),
            history: Vec::new(),
            weights: String::new(),
            optimizer: String::new(),
        };
        return Ok((fresh, None));
    };
    resume(objective, schedule, out, &saved, net)?;
    let s = &saved.state;
    let at =
        s.epoch as f64 + s.batch as f64 / objective.steps(schedule.seed, s.epoch).max(1) as f64;
    if schedule.progress && !nprt_io::staged() {
        eprintln!("resuming '{}' from epoch {at:.2}", out.display());
    }
    Ok((saved, Some(at)))
}

/// All that must match for a checkpoint to resume: the network's key, the learning rate and
/// the seed; for a decaying rate also its schedule and the run's length it decays over, so
/// that a finished run is not lengthened (the paper's constant rate may be).
pub(crate) fn run_key<O: Objective>(objective: &O, schedule: &Schedule) -> serde_json::Value {
    let mut key = serde_json::json!({
        "network": objective.run_key(),
        "learning_rate": schedule.learning_rate,
        "seed": schedule.seed,
    });
    if schedule.lr_schedule.needs_horizon() {
        key["lr_schedule"] = serde_json::json!({
            "name": schedule.lr_schedule.name(),
            "epochs": (schedule.epochs != usize::MAX).then_some(schedule.epochs),
            "minutes": schedule.minutes,
        });
    }
    key
}

/// Checks that `saved` belongs to this run and loads its weights.
fn resume<O: Objective>(
    objective: &O,
    schedule: &Schedule,
    out: &Path,
    saved: &Checkpoint,
    net: &mut O::Net,
) -> Result<()> {
    if saved.run != run_key(objective, schedule) {
        bail!(
            "model folder '{}' holds a run with other settings (network, dataset or hyper-parameters; a run with a decaying --schedule also keeps its --epochs and --minutes); choose another --out or delete it",
            out.display()
        );
    }
    checkpoint::restore_weights(out, saved, net, &objective.tag())
}
