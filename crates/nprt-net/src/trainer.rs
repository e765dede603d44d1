//! The one training loop, whatever the network: Adam as the paper (ε = 1e-8), checkpoints
//! with the optimiser's moments, exact resume, a divergence stop that keeps the last good
//! checkpoint, per-epoch validation, `loss.csv` and `loss.png`. What is trained, on which
//! batches and with which loss is an [`Objective`]: the Neural PRT designs and the Deep
//! Shading U-Net are two.
//!
//! Resume is exact because a batch is a function of the seed, the epoch and its index only,
//! and parameter ids (which key Adam's state) are stable.
//!
//! Batches are built on a thread of their own, a few ahead of the step that takes them, so
//! that a fast device does not wait for the host to gather its samples; the run reports how
//! its time split between steps, waiting for batches, validation and saving.

use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use burn::module::Module;
use burn::optim::{AdamConfig, GradientsParams, ModuleOptimizer};
use burn::tensor::Device;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use crate::checkpoint::{self, Checkpoint, RunState};
use crate::curves::{self, LossRow};
use crate::init::Init;
use crate::lr_schedule::LrSchedule;

pub const ADAM_EPSILON: f32 = 1e-8;
/// Training-loss rows per epoch in loss.csv.
const TRAIN_ROWS_PER_EPOCH: u64 = 20;

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
    /// Seconds between checkpoints inside an epoch (one is always written at each epoch end).
    #[serde(skip)]
    pub checkpoint_secs: f64,
    #[serde(skip)]
    pub progress: bool,
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
            if !(m > 0.0 && m.is_finite()) {
                bail!("the time budget must be a positive number of minutes, got {m}");
            }
        }
        Ok(())
    }

    /// The budget in seconds, if the run has one.
    fn budget_secs(&self) -> Option<f64> {
        self.minutes.map(|m| m * 60.0)
    }

    /// "epoch 3/20", or "epoch 3" for a run bounded by its time budget alone.
    fn epoch_label(&self, epoch: usize) -> String {
        if self.epochs == usize::MAX {
            format!("epoch {epoch}")
        } else {
            format!("epoch {epoch}/{}", self.epochs)
        }
    }
}

/// Batches built ahead of the step that takes them.
const BATCHES_AHEAD: usize = 2;

/// What one network's training is: its construction, its batches and its loss.
pub trait Objective: Sync {
    type Net: Module;
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
    /// The batch's mean loss, every parameter's gradient, and how many samples (pixels) the
    /// batch holds; `device` is an autodiff device.
    fn gradients(
        &self,
        net: &Self::Net,
        batch: &Self::Batch,
        device: &Device,
    ) -> (f64, GradientsParams, u64);
    /// Loss on held-out data with a network off the autodiff device; NaN where there is none.
    fn validation_loss(&self, net: &Self::Net, device: &Device) -> f64;
    /// Writes the model folder's own files (config and weights) for the network as it stands;
    /// `device` is the one [`Self::validation_loss`] runs on.
    fn save_model(
        &self,
        out: &Path,
        net: &Self::Net,
        schedule: &Schedule,
        state: &RunState,
        device: &Device,
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

/// Trains (or resumes training of) `objective`'s network in the model folder `out`.
pub fn train<O: Objective>(
    objective: &O,
    schedule: &Schedule,
    out: &Path,
    device: &Device,
) -> Result<TrainSummary> {
    schedule.check()?;
    let tag = objective.tag();
    let device = device.clone().autodiff();
    let inner = device.clone().inner();
    let mut net = objective.build(&mut Init::new(schedule.seed, &device));
    let mut optim = AdamConfig::new().with_epsilon(ADAM_EPSILON).init();
    std::fs::create_dir_all(checkpoint::dir(out))
        .with_context(|| format!("cannot create model folder '{}'", out.display()))?;

    let (mut ck, resumed_from_epoch) = match checkpoint::read(out)? {
        Some(saved) => {
            optim = resume(objective, schedule, out, &saved, &mut net, optim)?;
            let s = saved.state;
            let at = s.epoch as f64
                + s.batch as f64 / objective.steps(schedule.seed, s.epoch).max(1) as f64;
            if schedule.progress {
                eprintln!("resuming '{}' from epoch {at:.2}", out.display());
            }
            (saved, Some(at))
        }
        None => (
            Checkpoint {
                run: run_key(objective, schedule),
                state: RunState::default(),
                history: Vec::new(),
                weights: String::new(),
                optimizer: String::new(),
            },
            None,
        ),
    };

    // A time budget sets the run's length (and the bar's, in seconds); otherwise its batches do.
    let budget = schedule.budget_secs();
    let steps_in = |epoch: usize| objective.steps(schedule.seed, epoch);
    let total_batches: usize = match budget {
        Some(_) => 0,
        None => (0..schedule.epochs).map(steps_in).sum(),
    };
    let mut done_batches = (0..ck.state.epoch).map(steps_in).sum::<usize>() + ck.state.batch;
    let bar = match budget {
        Some(b) => nprt_io::progress_bar(
            schedule.progress,
            b.ceil() as u64,
            &format!("training {tag}"),
            "s",
        ),
        None => nprt_io::progress_bar(
            schedule.progress,
            total_batches as u64,
            &format!("training {tag}"),
            "batches",
        ),
    };
    bar.set_position(match budget {
        Some(_) => ck.state.seconds as u64,
        None => done_batches as u64,
    });
    bar.reset_eta();
    let out_of_time = |seconds: f64| budget.is_some_and(|b| seconds >= b);
    let started = Instant::now();
    let seconds_before = ck.state.seconds;
    let mut last_checkpoint = Instant::now();
    let (mut row_sum, mut row_n) = (0.0f64, 0u64);
    let mut last_train = f64::NAN;
    let mut guard = DivergenceGuard::default();

    let mut split = TimeSplit::default();
    let mut trained = false;

    while ck.state.epoch < schedule.epochs && !out_of_time(ck.state.seconds) {
        trained = true;
        let epoch = ck.state.epoch;
        let total = steps_in(epoch);
        let row_every = (total as u64).div_ceil(TRAIN_ROWS_PER_EPOCH).max(1);
        let from = ck.state.batch;
        // The network moves into the scope and back out, so that the optimiser updates the
        // only handle to its tensors.
        net = std::thread::scope(|scope| -> Result<O::Net> {
            let mut net = net;
            let (sender, batches) = std::sync::mpsc::sync_channel(BATCHES_AHEAD);
            scope.spawn(move || {
                for batch in objective.batches(schedule.seed, epoch, from) {
                    if sender.send(batch).is_err() {
                        break; // the epoch stopped early (time budget or an error)
                    }
                }
            });
            loop {
                let waiting = Instant::now();
                let Ok(batch) = batches.recv() else { break };
                split.batch_wait += since(waiting);
                let stepping = Instant::now();
                let progress = match budget {
                    Some(b) => ck.state.seconds / b,
                    None => done_batches as f64 / total_batches.max(1) as f64,
                };
                let lr = schedule.learning_rate * schedule.lr_schedule.factor(progress);
                let (value, grads, samples) = objective.gradients(&net, &batch, &device);
                if let Some(why) = guard.check(value, ck.state.step) {
                    bar.abandon();
                    let kept = if checkpoint::exists(out) {
                        format!(
                            "the last good checkpoint in '{}' is kept",
                            checkpoint::dir(out).display()
                        )
                    } else {
                        "no checkpoint had been written yet".to_string()
                    };
                    bail!(
                        "training diverged at epoch {} step {} ({why}); {kept}; lower --lr and use another --out",
                        epoch + 1,
                        ck.state.step
                    );
                }
                net = optim.step(lr, net, grads);
                split.steps += since(stepping);
                done_batches += 1;
                let s = &mut ck.state;
                s.batch += 1;
                s.step += 1;
                s.samples += samples;
                s.seconds = seconds_before + started.elapsed().as_secs_f64();
                row_sum += value;
                row_n += 1;
                last_train = value;
                if s.step.is_multiple_of(row_every) {
                    ck.history.push(LossRow {
                        step: s.step,
                        epoch: epoch as f64 + s.batch as f64 / total as f64,
                        samples: s.samples,
                        seconds: s.seconds,
                        train: Some(row_sum / row_n as f64),
                        val: None,
                    });
                    (row_sum, row_n) = (0.0, 0);
                }
                match budget {
                    Some(_) => bar.set_position(s.seconds as u64),
                    None => bar.inc(1),
                }
                bar.set_message(format!(
                    "{} loss {:.4} {:.0}K samples/s",
                    schedule.epoch_label(epoch + 1),
                    guard.ema,
                    s.samples as f64 / s.seconds.max(1e-9) / 1e3
                ));
                if out_of_time(s.seconds) {
                    break;
                }
                if last_checkpoint.elapsed().as_secs_f64() > schedule.checkpoint_secs {
                    let saving = Instant::now();
                    save(objective, schedule, out, &mut ck, &net, &optim, &inner)?;
                    split.saving += since(saving);
                    last_checkpoint = Instant::now();
                }
            }
            Ok(net)
        })?;
        // The epoch ended, or the budget ran out within it: validate and save either way.
        let validating = Instant::now();
        let val = objective.validation_loss(&net.valid(), &inner);
        split.validation += since(validating);
        let s = &mut ck.state;
        if s.batch >= total {
            s.epoch += 1;
            s.batch = 0;
        }
        ck.history.push(LossRow {
            step: s.step,
            epoch: s.epoch as f64 + s.batch as f64 / total.max(1) as f64,
            samples: s.samples,
            seconds: s.seconds,
            train: (row_n > 0).then(|| row_sum / row_n as f64),
            val: Some(val),
        });
        (row_sum, row_n) = (0.0, 0);
        if schedule.progress {
            // Also when the bar is hidden (output not a terminal), so logs show progress.
            let train = ck.history.iter().rev().find_map(|r| r.train);
            bar.suspend(|| {
                eprintln!(
                    "{}: train loss {:.5}, validation loss {val:.5}, {:.0} K samples/s, {:.0} s",
                    schedule.epoch_label(s.epoch),
                    train.unwrap_or(last_train),
                    s.samples as f64 / s.seconds.max(1e-9) / 1e3,
                    s.seconds
                )
            });
        }
        let saving = Instant::now();
        save(objective, schedule, out, &mut ck, &net, &optim, &inner)?;
        split.saving += since(saving);
        last_checkpoint = Instant::now();
    }
    bar.finish_and_clear();
    if !trained {
        // A finished run asked again: its model files follow this invocation's options (the
        // output calibration, say), since nothing else will write them.
        objective.save_model(out, &net, schedule, &ck.state, &inner)?;
    }
    let last = |f: fn(&LossRow) -> Option<f64>| ck.history.iter().rev().find_map(f);
    Ok(TrainSummary {
        epochs: ck.state.epoch as f64
            + ck.state.batch as f64 / steps_in(ck.state.epoch).max(1) as f64,
        steps: ck.state.step,
        samples: ck.state.samples,
        seconds: ck.state.seconds,
        final_train: last(|r| r.train).unwrap_or(last_train),
        final_val: last(|r| r.val).unwrap_or(f64::NAN),
        resumed_from_epoch,
        split,
    })
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

/// Checks that `saved` belongs to this run and loads its weights and optimiser state.
fn resume<O: Objective>(
    objective: &O,
    schedule: &Schedule,
    out: &Path,
    saved: &Checkpoint,
    net: &mut O::Net,
    optim: ModuleOptimizer,
) -> Result<ModuleOptimizer> {
    if saved.run != run_key(objective, schedule) {
        bail!(
            "model folder '{}' holds a run with other settings (network, dataset or hyper-parameters; a run with a decaying --schedule also keeps its --epochs and --minutes); choose another --out or delete it",
            out.display()
        );
    }
    checkpoint::restore(out, saved, net, optim, &objective.tag())
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

/// The checkpoint, then the model folder's own files, loss.csv and loss.png; `device` is the
/// one validation runs on.
fn save<O: Objective>(
    objective: &O,
    schedule: &Schedule,
    out: &Path,
    ck: &mut Checkpoint,
    net: &O::Net,
    optim: &ModuleOptimizer,
    device: &Device,
) -> Result<()> {
    checkpoint::write(out, ck, net, optim, &objective.tag())?;
    objective.save_model(out, net, schedule, &ck.state, device)?;
    curves::write_csv(&out.join("loss.csv"), &ck.history)?;
    curves::plot(&out.join("loss.png"), &ck.history, &objective.title())
}
