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
use crate::optimiser::EngineSteps;
use crate::parameters::Parameters;
use crate::training::checkpoint::{self, Checkpoint, RunState};
use crate::training::loss_curves::{self as curves, LossRow};
use crate::training::schedule::Schedule;
use crate::training::snapshot::SnapshotPlan;

/// Training-loss rows per epoch in loss.csv.
const TRAIN_ROWS_PER_EPOCH: u64 = 20;

/// Seconds since the last checkpoint after which an epoch's end writes one (the run's end
/// always does): a small dataset's epochs take a GPU milliseconds, and writing the checkpoint,
/// the model and the plot after each took a quarter of a 30-second run on an H200.
const EPOCH_CHECKPOINT_SECS: f64 = 10.0;

/// Batches built ahead of the step that takes them.
const BATCHES_AHEAD: usize = 2;

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

/// Seconds since `start`.
fn since(start: Instant) -> f64 {
    start.elapsed().as_secs_f64()
}

/// The random stream of one part (`stream`) of one epoch: shuffles depend on nothing else.
pub fn epoch_rng(seed: u64, epoch: u64, stream: u64) -> Pcg64Mcg {
    let key = [seed, epoch, stream].map(u64::to_le_bytes).concat();
    let h = blake3::hash(&key);
    let mut first = [0; 8];
    first.copy_from_slice(&h.as_bytes()[..8]);
    Pcg64Mcg::seed_from_u64(u64::from_le_bytes(first))
}

/// What a run tells its caller at each epoch's end (the row it adds to its loss curves), and
/// whether to go on: `false` ends the run there, saved as the end of a time budget saves it,
/// so that the same call resumes it later. The command line goes on; Python's `nprt.train`
/// passes its callback's answer and stops on Ctrl-C.
pub type Watch<'a> = &'a (dyn Fn(&LossRow) -> bool + Sync);

/// Trains (or resumes training of) `objective`'s network in the model folder `out`, telling
/// `watch` each epoch's end.
pub fn train<O: Objective>(
    objective: &O,
    schedule: &Schedule,
    out: &Path,
    watch: Watch,
) -> Result<TrainSummary> {
    schedule.check()?;
    if out.join(nprt_data::dataset::MANIFEST).exists() {
        bail!(
            "'{}' is a dataset folder (it holds {}); a model goes into a folder of its own \
             (--out)",
            out.display(),
            nprt_data::dataset::MANIFEST
        );
    }
    let mut net = objective.build(&mut Init::new(schedule.seed));
    std::fs::create_dir_all(checkpoint::dir(out))
        .with_context(|| format!("cannot create model folder '{}'", out.display()))?;
    let _lock = nprt_io::lock_folder(out, "model folder", "--out")?;
    let (ck, resumed_from_epoch) = start(objective, schedule, out, &mut net)?;
    let mut steps = objective.engine_steps(&net)?;
    if resumed_from_epoch.is_some() {
        checkpoint::restore_optimiser(out, &ck, steps.as_mut())?;
    }
    let mut run = Run::new(objective, schedule, out, ck);
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
        go_on = watch(run.ck.history.last().expect("an epoch's end adds a row"));
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
        objective.save_model(out, &net, schedule, &run.ck.state)?;
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

/// A run between steps: the checkpoint it builds, the loss-table row being summed, the
/// divergence guard, where the time went and the progress bar.
struct Run<'s, O: Objective> {
    objective: &'s O,
    schedule: &'s Schedule,
    /// The model folder.
    out: &'s Path,
    ck: Checkpoint,
    /// Seconds of training the run may take, when it has a time budget.
    budget: Option<f64>,
    total_batches: usize,
    done_batches: usize,
    /// Steps queued on a device whose loss is not back yet (counted in the learning rate's
    /// progress, so that it does not depend on when losses are read).
    queued: usize,
    bar: nprt_io::ProgressBar,
    started: Instant,
    seconds_before: f64,
    last_checkpoint: Instant,
    row_sum: f64,
    row_n: u64,
    last_train: f64,
    guard: DivergenceGuard,
    split: TimeSplit,
    steps_on: String,
    snapshots: SnapshotPlan,
}

impl<'s, O: Objective> Run<'s, O> {
    fn new(objective: &'s O, schedule: &'s Schedule, out: &'s Path, ck: Checkpoint) -> Self {
        // A time budget sets the run's length (and the bar's, in seconds); otherwise its
        // batches do.
        let budget = schedule.budget_secs();
        let steps_in = |epoch: usize| objective.steps(schedule.seed, epoch);
        let total_batches = match budget {
            Some(_) => 0,
            None => (0..schedule.epochs).map(steps_in).sum(),
        };
        // Every batch done was a step: read, not replayed epoch by epoch (a state edited to
        // 10⁹ epochs and steps replayed a billion epochs' plans).
        let done_batches = ck.state.step as usize;
        let what = format!("training {}", objective.tag());
        let bar = match budget {
            Some(b) => nprt_io::progress_bar(schedule.progress, b.ceil() as u64, &what, "s"),
            None => {
                nprt_io::progress_bar(schedule.progress, total_batches as u64, &what, "batches")
            }
        };
        bar.set_position(match budget {
            Some(_) => ck.state.seconds as u64,
            None => done_batches as u64,
        });
        bar.reset_eta();
        Run {
            objective,
            schedule,
            out,
            budget,
            total_batches,
            done_batches,
            queued: 0,
            bar,
            started: Instant::now(),
            seconds_before: ck.state.seconds,
            last_checkpoint: Instant::now(),
            row_sum: 0.0,
            row_n: 0,
            last_train: f64::NAN,
            guard: DivergenceGuard::default(),
            split: TimeSplit::default(),
            steps_on: String::new(),
            snapshots: SnapshotPlan::new(
                &schedule.snapshots,
                out,
                ck.state.seconds,
                ck.state.epoch,
            ),
            ck,
        }
    }

    /// Whether the run's time budget is spent, or this call's pause has come.
    fn out_of_time(&self) -> bool {
        self.budget_spent() || self.pausing()
    }

    /// Whether the run's time budget, if it has one, is spent.
    fn budget_spent(&self) -> bool {
        self.budget.is_some_and(|b| self.ck.state.seconds >= b)
    }

    /// Whether this call has trained its `pause_after`.
    fn pausing(&self) -> bool {
        let this_call = self.ck.state.seconds - self.seconds_before;
        self.schedule.pause_secs().is_some_and(|p| this_call >= p)
    }

    /// Batches in `epoch`.
    fn steps_in(&self, epoch: usize) -> usize {
        self.objective.steps(self.schedule.seed, epoch)
    }

    /// The learning rate of the next step.
    fn learning_rate(&self) -> f64 {
        let progress = match self.budget {
            Some(b) => self.ck.state.seconds / b,
            None => (self.done_batches + self.queued) as f64 / self.total_batches.max(1) as f64,
        };
        self.schedule.learning_rate * self.schedule.lr_schedule.factor(progress)
    }

    /// One epoch of `total` batches from the checkpoint's batch on, until its end or the time
    /// budget's, with checkpoints (of `net`, brought up to date) as due. Batches are built on a
    /// thread of their own.
    fn epoch(
        &mut self,
        total: usize,
        net: &mut O::Net,
        steps: &mut dyn EngineSteps<O::Net, O::Batch>,
    ) -> Result<()> {
        let (objective, epoch) = (self.objective, self.ck.state.epoch);
        let row_every = (total as u64).div_ceil(TRAIN_ROWS_PER_EPOCH).max(1);
        let from = self.ck.state.batch;
        let seed = self.schedule.seed;
        std::thread::scope(|scope| -> Result<()> {
            let (sender, batches) = std::sync::mpsc::sync_channel(BATCHES_AHEAD);
            scope.spawn(move || {
                for batch in objective.batches(seed, epoch, from) {
                    if sender.send(batch).is_err() {
                        break; // the epoch stopped early (time budget or an error)
                    }
                }
            });
            loop {
                let waiting = Instant::now();
                let Ok(batch) = batches.recv() else { break };
                self.split.batch_wait += since(waiting);
                let stepping = Instant::now();
                let lr = self.learning_rate();
                self.queued += 1;
                // A device's step returns the one before it, so that the device does not wait
                // for the host.
                let done = steps.step(&batch, lr)?;
                self.split.steps += since(stepping);
                if let Some((value, samples)) = done {
                    self.record_step(value, samples, epoch, total, row_every)?;
                }
                if self.snapshots.due(self.ck.state.seconds, epoch) {
                    self.settle(steps, epoch, total, row_every)?;
                    steps.store(net);
                    self.take_snapshots(net)?;
                }
                if self.out_of_time() {
                    break;
                }
                if self.last_checkpoint.elapsed().as_secs_f64() > self.schedule.checkpoint_secs {
                    self.settle(steps, epoch, total, row_every)?;
                    steps.store(net);
                    self.save(net, steps)?;
                }
            }
            self.settle(steps, epoch, total, row_every)
        })
    }

    /// Stops the run when the loss of the step just taken says it diverged.
    fn check_divergence(&mut self, value: f64, epoch: usize) -> Result<()> {
        match self.guard.check(value, self.ck.state.step) {
            Some(why) => Err(self.diverged(&why, epoch)),
            None => Ok(()),
        }
    }

    /// The error that ends a diverged run (`why`: the loss that says so) in epoch `epoch`. The
    /// model files go: saved as the weights grew, they may hold weights no later command should
    /// load (`render` made black frames of |w| ≈ 1e30 with exit 0).
    fn diverged(&mut self, why: &str, epoch: usize) -> anyhow::Error {
        // Data changed under the run (random bytes over its pack) makes a run diverge too:
        // said as such, not blamed on --lr.
        if let Err(e) = self.objective.check_data() {
            return self.abandon(e, epoch);
        }
        let step = self.ck.state.step;
        let files = self.remove_model_files();
        anyhow::anyhow!(
            "training diverged at epoch {} step {step} ({why}); {files}; lower --lr and use another --out",
            epoch + 1,
        )
    }

    /// Stops a run whose data changed while it read it (`e` says how), its model files removed.
    fn abandon(&mut self, e: anyhow::Error, epoch: usize) -> anyhow::Error {
        let step = self.ck.state.step;
        let files = self.remove_model_files();
        e.context(format!(
            "training stopped at epoch {} step {step}: the dataset changed while the run read it \
             (it was checked when the run began); {files}; leave the dataset alone during a run \
             and run it again",
            epoch + 1
        ))
    }

    /// Removes the model folder's own files, so that no later command loads a model from a
    /// failed run; says what was removed and what is kept.
    fn remove_model_files(&mut self) -> String {
        self.bar.abandon();
        let removed = (self.objective.model_files().iter())
            .filter(|f| std::fs::remove_file(self.out.join(f)).is_ok())
            .count();
        let model = match removed {
            0 => String::new(),
            _ => "its model files are removed; ".into(),
        };
        let kept = if checkpoint::exists(self.out) {
            format!(
                "the last checkpoint in '{}' is kept for inspection",
                checkpoint::dir(self.out).display()
            )
        } else {
            "no checkpoint had been written yet".to_string()
        };
        format!("{model}{kept}")
    }

    /// Waits for the last queued step on a device and counts it: before saving, and at the
    /// end of an epoch.
    fn settle(
        &mut self,
        steps: &mut dyn EngineSteps<O::Net, O::Batch>,
        epoch: usize,
        total: usize,
        row_every: u64,
    ) -> Result<()> {
        // Waiting for the step is the step's time.
        let waiting = Instant::now();
        let last = steps.finish()?;
        self.split.steps += since(waiting);
        if let Some((value, samples)) = last {
            self.record_step(value, samples, epoch, total, row_every)?;
        }
        Ok(())
    }

    /// Counts a finished step and its loss (stopping the run if the loss says it diverged),
    /// adding a loss-table row every `row_every` steps.
    fn record_step(
        &mut self,
        value: f64,
        samples: u64,
        epoch: usize,
        total: usize,
        row_every: u64,
    ) -> Result<()> {
        self.check_divergence(value, epoch)?;
        self.queued -= 1;
        self.done_batches += 1;
        let s = &mut self.ck.state;
        s.batch += 1;
        s.step += 1;
        s.samples += samples;
        s.seconds = self.seconds_before + self.started.elapsed().as_secs_f64();
        self.row_sum += value;
        self.row_n += 1;
        self.last_train = value;
        if s.step.is_multiple_of(row_every) {
            self.ck.history.push(LossRow {
                step: s.step,
                epoch: epoch as f64 + s.batch as f64 / total as f64,
                samples: s.samples,
                seconds: s.seconds,
                train: Some(self.row_sum / self.row_n as f64),
                val: None,
            });
            (self.row_sum, self.row_n) = (0.0, 0);
        }
        match self.budget {
            Some(_) => self.bar.set_position(s.seconds as u64),
            None => self.bar.inc(1),
        }
        self.bar.set_message(format!(
            "{} loss {:.4} {:.0}K samples/s",
            self.schedule.epoch_label(epoch + 1),
            self.guard.ema,
            s.samples as f64 / s.seconds.max(1e-9) / 1e3
        ));
        Ok(())
    }

    /// Closes the epoch of `total` batches (or the part of it the budget left) with its
    /// validation loss `val`.
    fn end_epoch(&mut self, val: f64, total: usize) {
        let s = &mut self.ck.state;
        if s.batch >= total {
            s.epoch += 1;
            s.batch = 0;
        }
        // The steps since the previous row; where a row closed them just before, that row's
        // figure: an epoch's row always says its training loss (Python's callback gets it).
        let train = match self.row_n {
            0 => self.ck.history.last().and_then(|r| r.train),
            n => Some(self.row_sum / n as f64),
        };
        self.ck.history.push(LossRow {
            step: s.step,
            epoch: s.epoch as f64 + s.batch as f64 / total.max(1) as f64,
            samples: s.samples,
            seconds: s.seconds,
            train,
            val: Some(val),
        });
        (self.row_sum, self.row_n) = (0.0, 0);
        if self.schedule.progress && !nprt_io::staged() {
            // Also when the bar is hidden (output not a terminal), so logs show progress.
            let train = self.ck.history.iter().rev().find_map(|r| r.train);
            self.bar.suspend(|| {
                eprintln!(
                    "{}: train loss {:.5}, validation loss {val:.5}, {:.0} K samples/s, {:.0} s",
                    self.schedule.epoch_label(s.epoch),
                    train.unwrap_or(self.last_train),
                    s.samples as f64 / s.seconds.max(1e-9) / 1e3,
                    s.seconds
                )
            });
        }
    }

    /// Keeps `net` (up to date) at every snapshot point reached.
    fn take_snapshots(&mut self, net: &O::Net) -> Result<()> {
        let (objective, schedule, out, state) =
            (self.objective, self.schedule, self.out, &self.ck.state);
        let saving = Instant::now();
        (self.snapshots).take(out, state.seconds, state.epoch, |dir| {
            objective.save_model(dir, net, schedule, state)
        })?;
        self.split.saving += since(saving);
        Ok(())
    }

    /// Writes the checkpoint, the model files and the loss curves.
    fn save(&mut self, net: &O::Net, steps: &dyn EngineSteps<O::Net, O::Batch>) -> Result<()> {
        let saving = Instant::now();
        let (objective, out, ck) = (self.objective, self.out, &mut self.ck);
        checkpoint::write(out, ck, net, steps, &objective.tag())?;
        objective.save_model(out, net, self.schedule, &ck.state)?;
        curves::write_csv(&out.join("loss.csv"), &ck.history)?;
        curves::plot(&out.join("loss.png"), &ck.history, &objective.title())?;
        self.split.saving += since(saving);
        self.last_checkpoint = Instant::now();
        Ok(())
    }

    fn summary(&self, resumed_from_epoch: Option<f64>) -> TrainSummary {
        let state = self.ck.state;
        let last = |f: fn(&LossRow) -> Option<f64>| self.ck.history.iter().rev().find_map(f);
        TrainSummary {
            epochs: state.epoch as f64
                + state.batch as f64 / self.steps_in(state.epoch).max(1) as f64,
            steps: state.step,
            samples: state.samples,
            seconds: state.seconds,
            final_train: last(|r| r.train).unwrap_or(self.last_train),
            final_val: last(|r| r.val).unwrap_or(f64::NAN),
            resumed_from_epoch,
            paused: self.pausing() && state.epoch < self.schedule.epochs && !self.budget_spent(),
            steps_on: self.steps_on.clone(),
            split: self.split,
        }
    }
}

/// All that must match for a checkpoint to resume: the network's key, the learning rate and
/// the seed; for a decaying rate also its schedule and the run's length it decays over, so
/// that a finished run is not lengthened (the paper's constant rate may be).
fn run_key<O: Objective>(objective: &O, schedule: &Schedule) -> serde_json::Value {
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

/// Stops a run whose loss is not finite or whose running mean rose ten times above its best
/// (measured after 200 steps, once the start's transient is over).
struct DivergenceGuard {
    ema: f64,
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
    fn check(&mut self, loss: f64, step: u64) -> Option<String> {
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
