//! A training run between its steps: the checkpoint it builds, the loss-table row being
//! summed, the divergence guard, the time budget, where the time went and the progress bar;
//! one epoch's steps with their batches built on a thread of their own. The loop around it
//! (start, resume, validation at epochs' ends) is the `training_loop` module.

use std::path::Path;
use std::time::Instant;

use anyhow::Result;

use crate::optimiser::EngineSteps;
use crate::training::checkpoint::{self, Checkpoint};
use crate::training::divergence::DivergenceGuard;
use crate::training::live::LiveRun;
use crate::training::loss_curves::{self as curves, LossRow};
use crate::training::objective::{Objective, TrainSummary};
use crate::training::schedule::Schedule;
use crate::training::snapshot::SnapshotPlan;
use crate::training::time_split::TimeSplit;

/// Training-loss rows per epoch in loss.csv.
const TRAIN_ROWS_PER_EPOCH: u64 = 20;

/// Batches built ahead of the step that takes them.
const BATCHES_AHEAD: usize = 2;

/// Seconds since `start`.
pub(crate) fn since(start: Instant) -> f64 {
    start.elapsed().as_secs_f64()
}

/// A run between steps: the checkpoint it builds, the loss-table row being summed, the
/// divergence guard, where the time went and the progress bar.
pub(crate) struct Run<'s, O: Objective> {
    pub(super) objective: &'s O,
    /// The run's schedule, its time budget lengthened where a live run's watcher asked.
    pub(super) schedule: Schedule,
    /// The model folder.
    pub(super) out: &'s Path,
    pub(super) ck: Checkpoint,
    pub(super) total_batches: usize,
    pub(super) done_batches: usize,
    /// Steps queued on a device whose loss is not back yet (counted in the learning rate's
    /// progress, so that it does not depend on when losses are read).
    pub(super) queued: usize,
    pub(super) bar: nprt_io::ProgressBar,
    pub(super) started: Instant,
    pub(super) seconds_before: f64,
    pub(super) last_checkpoint: Instant,
    pub(super) row_sum: f64,
    pub(super) row_n: u64,
    pub(super) last_train: f64,
    pub(super) guard: DivergenceGuard,
    pub(super) split: TimeSplit,
    pub(super) steps_on: String,
    pub(super) snapshots: SnapshotPlan,
    pub(super) live: Option<&'s LiveRun>,
    /// Seconds paused by the live run's watcher, not counted as training.
    pub(super) idle: f64,
    /// Training seconds when the live run's model was last published.
    pub(super) published_at: f64,
}

impl<'s, O: Objective> Run<'s, O> {
    pub(super) fn new(
        objective: &'s O,
        schedule: &Schedule,
        out: &'s Path,
        ck: Checkpoint,
        live: Option<&'s LiveRun>,
    ) -> Self {
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
            schedule: schedule.clone(),
            out,
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
            published_at: ck.state.seconds,
            ck,
            live,
            idle: 0.0,
        }
    }

    /// Seconds of training the run may take, when it has a time budget.
    pub(super) fn budget(&self) -> Option<f64> {
        self.schedule.budget_secs()
    }

    /// Whether the run's time budget is spent, or this call's pause has come.
    pub(super) fn out_of_time(&self) -> bool {
        self.budget_spent() || self.pausing()
    }

    /// Whether the run's time budget, if it has one, is spent.
    pub(super) fn budget_spent(&self) -> bool {
        self.budget().is_some_and(|b| self.ck.state.seconds >= b)
    }

    /// Whether this call has trained its `pause_after`.
    pub(super) fn pausing(&self) -> bool {
        let this_call = self.ck.state.seconds - self.seconds_before;
        self.schedule.pause_secs().is_some_and(|p| this_call >= p)
    }

    /// Batches in `epoch`.
    pub(super) fn steps_in(&self, epoch: usize) -> usize {
        self.objective.steps(self.schedule.seed, epoch)
    }

    /// The learning rate of the next step.
    pub(super) fn learning_rate(&self) -> f64 {
        let progress = match self.budget() {
            Some(b) => self.ck.state.seconds / b,
            None => (self.done_batches + self.queued) as f64 / self.total_batches.max(1) as f64,
        };
        self.schedule.learning_rate * self.schedule.lr_schedule.factor(progress)
    }

    /// One epoch of `total` batches from the checkpoint's batch on, until its end or the time
    /// budget's, with checkpoints (of `net`, brought up to date) as due. Batches are built on a
    /// thread of their own.
    pub(super) fn epoch(
        &mut self,
        total: usize,
        net: &mut O::Net,
        steps: &mut dyn EngineSteps<O::Net, O::Batch>,
    ) -> Result<()> {
        let (objective, epoch) = (self.objective, self.ck.state.epoch);
        let row_every = (total as u64).div_ceil(TRAIN_ROWS_PER_EPOCH).max(1);
        let from = self.ck.state.batch;
        let seed = self.schedule.seed;
        let live = self.live;
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
                if let Some(live) = live {
                    self.attend(live, net, steps, (epoch, total, row_every))?;
                }
                if self.out_of_time() || self.stopped() {
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
    pub(super) fn check_divergence(&mut self, value: f64, epoch: usize) -> Result<()> {
        match self.guard.check(value, self.ck.state.step) {
            Some(why) => Err(self.diverged(&why, epoch)),
            None => Ok(()),
        }
    }

    /// The error that ends a diverged run (`why`: the loss that says so) in epoch `epoch`. The
    /// model files go: saved as the weights grew, they may hold weights no later command should
    /// load (`render` made black frames of |w| ≈ 1e30 with exit 0).
    pub(super) fn diverged(&mut self, why: &str, epoch: usize) -> anyhow::Error {
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
    pub(super) fn abandon(&mut self, e: anyhow::Error, epoch: usize) -> anyhow::Error {
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
    pub(super) fn remove_model_files(&mut self) -> String {
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
    pub(super) fn settle(
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
    pub(super) fn record_step(
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
        s.seconds = self.seconds_before + self.started.elapsed().as_secs_f64() - self.idle;
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
        match self.schedule.budget_secs() {
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
    pub(super) fn end_epoch(&mut self, val: f64, total: usize) {
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
    pub(super) fn take_snapshots(&mut self, net: &O::Net) -> Result<()> {
        let (objective, schedule, out, state) =
            (self.objective, &self.schedule, self.out, &self.ck.state);
        let saving = Instant::now();
        (self.snapshots).take(out, state.seconds, state.epoch, |dir| {
            objective.save_model(dir, net, schedule, state)
        })?;
        self.split.saving += since(saving);
        Ok(())
    }

    /// Writes the checkpoint, the model files and the loss curves.
    pub(super) fn save(
        &mut self,
        net: &O::Net,
        steps: &dyn EngineSteps<O::Net, O::Batch>,
    ) -> Result<()> {
        let saving = Instant::now();
        let (objective, out, ck) = (self.objective, self.out, &mut self.ck);
        checkpoint::write(out, ck, net, steps, &objective.tag())?;
        objective.save_model(out, net, &self.schedule, &ck.state)?;
        curves::write_csv(&out.join("loss.csv"), &ck.history)?;
        curves::plot(&out.join("loss.png"), &ck.history, &objective.title())?;
        self.split.saving += since(saving);
        self.last_checkpoint = Instant::now();
        Ok(())
    }

    pub(super) fn summary(&self, resumed_from_epoch: Option<f64>) -> TrainSummary {
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
