//! Training a Neural PRT design as the paper does: Adam at 1e-4, L1 on log(1 + x), the
//! encoder trained jointly, batches that mix foreground pixels of several views, each lit by
//! its own rotated map. The loop itself (checkpoints, exact resume) is
//! [`crate::training::training_loop`].
//!
//! A run lives in its model folder: the model (config and latest weights), `loss.csv`,
//! `loss.png` and `checkpoint/`.

use std::path::Path;
use std::sync::Mutex;

use anyhow::{bail, Context, Result};

use crate::engine::Engine;
use crate::init::Init;
use crate::loss::Loss;
use crate::model::config::ModelConfig;
use crate::model::folder::{
    save_model, ModelFile, CONFIG_FILE, MODEL_FORMAT, MODEL_VERSION, WEIGHTS_FILE,
};
use crate::network::nprt_net::NprtNet;
use crate::optimiser::{EngineSteps, ADAM_EPSILON};
use crate::parameters::Parameters;
use crate::precision::Precision;
use crate::training::batch::Batch;
use crate::training::calibration::{level_gain, Calibration, LEVEL_SAMPLES};
use crate::training::checkpoint::RunState;
use crate::training::epoch_plan::{group_batches, EpochPlan};
use crate::training::host_steps::HostSteps;
use crate::training::live::LiveRun;
use crate::training::schedule::Schedule;
use crate::training::train_options::{Gather, Targets, TrainOptions};
use crate::training::training_loop::{self, Objective, Steps, TrainSummary, Watch};
use crate::training::training_set::{TrainingSet, ViewSamples};
use crate::training::validation::validation_loss;

/// A Neural PRT design learning a dataset's pixels.
struct PixelObjective<'a> {
    set: &'a TrainingSet,
    config: &'a ModelConfig,
    opts: &'a TrainOptions,
    /// The model file as last saved, returned to the caller.
    saved: Mutex<Option<ModelFile>>,
    /// Whether the steps run on our own GPU kernels (`--device gpu` or `wgpu`).
    kernels: bool,
    /// Transfer coefficients per channel the model learns (`--targets transfer`; 0: radiance).
    transfer: usize,
}

impl PixelObjective<'_> {
    /// Whether the kernels hold the dataset (their steps are refused where it cannot go up),
    /// so that batches are only picked on the host. Transfer vectors are not uploaded with
    /// it: their batches are gathered on the host.
    fn resident(&self) -> bool {
        self.kernels && self.opts.gather == Gather::Device && self.transfer == 0
    }
}

impl Objective for PixelObjective<'_> {
    type Net = NprtNet;
    type Batch = Batch;

    fn tag(&self) -> String {
        self.config.weights_tag()
    }

    fn title(&self) -> String {
        format!(
            "{} ({})",
            self.config.design.name(),
            self.config.activation.name()
        )
    }

    fn run_key(&self) -> serde_json::Value {
        let mut key = serde_json::json!({
            "config": self.config,
            "dataset_hash": self.set.dataset_hash,
            "batch_size": self.opts.batch_size,
            "views_per_batch": self.opts.views_per_batch,
            "val_samples": self.opts.val_samples,
            "loss": self.opts.loss,
        });
        // Named only where it is not f32, so that runs from before the choice still resume.
        if self.opts.precision != Precision::F32 {
            key["precision"] = serde_json::json!(self.opts.precision);
        }
        if self.opts.targets != Targets::Radiance {
            key["targets"] = serde_json::json!(self.opts.targets);
        }
        key
    }

    fn build(&self, init: &mut Init) -> NprtNet {
        self.config
            .build(init)
            .shift_output_level(self.set.log_relative_level())
    }

    fn steps(&self, seed: u64, epoch: usize) -> usize {
        EpochPlan::new(self.set, self.opts, seed, epoch).total()
    }

    fn batches(&self, seed: u64, epoch: usize, from: usize) -> impl Iterator<Item = Batch> + '_ {
        let plan = EpochPlan::new(self.set, self.opts, seed, epoch);
        let starts: Vec<usize> = plan
            .batches
            .iter()
            .scan(0, |acc, &n| {
                *acc += n;
                Some(*acc - n)
            })
            .collect();
        plan.groups
            .into_iter()
            .zip(plan.batches)
            .zip(starts)
            .enumerate()
            .filter(move |(_, ((_, count), start))| start + count > from)
            .flat_map(move |(g, ((group, count), start))| {
                let views = GroupViews(group.iter().map(|&v| &self.set.train[v]).collect());
                let batches = group_batches(&views.0, count, seed, epoch, g);
                batches
                    .into_iter()
                    .skip(from.saturating_sub(start))
                    .map(move |samples| match self.resident() {
                        true => Batch::picked(&group, &views.0, &samples),
                        false => Batch::gather(&views.0, &samples, self.transfer),
                    })
            })
    }

    fn engine_steps(&self, net: &NprtNet) -> Result<Steps<'_, Self>> {
        #[cfg(feature = "gpu")]
        if self.kernels {
            let dataset = self.resident().then_some(self.set);
            let steps = crate::training::kernel_steps::KernelSteps::new(
                net,
                self.opts.loss,
                self.opts.precision,
                dataset,
            )?;
            return Ok(Box::new(steps));
        }
        let loss = self.opts.loss;
        Ok(Box::new(HostSteps::new(
            net,
            move |net: &NprtNet, batch: &Batch| {
                let (value, grads) = crate::cpu::gradients(net, &batch.samples(), loss);
                (value, grads, batch.len() as u64)
            },
            |net: &NprtNet, batch: &Batch| {
                let prediction = crate::cpu::predict(net, &batch.samples());
                Loss::LogL1.mean(&prediction, &batch.radiance)
            },
        )))
    }

    fn validation_loss(&self, steps: &mut dyn EngineSteps<NprtNet, Batch>) -> Result<f64> {
        let (samples, batch_size) = (self.opts.val_samples, self.opts.batch_size);
        validation_loss(self.set, samples, batch_size, |b| steps.loss(b))
    }

    fn model_files(&self) -> [&'static str; 2] {
        [CONFIG_FILE, WEIGHTS_FILE]
    }

    fn check_data(&self) -> Result<()> {
        self.set.pack.check_records()
    }

    fn save_model(
        &self,
        out: &Path,
        net: &NprtNet,
        schedule: &Schedule,
        state: &RunState,
    ) -> Result<()> {
        let file = self.model_file(net, schedule, state);
        save_model(out, &file, net)?;
        *self.saved.lock().unwrap_or_else(|e| e.into_inner()) = Some(file);
        Ok(())
    }

    fn publish(&self, net: &NprtNet, schedule: &Schedule, state: &RunState, live: &LiveRun) {
        live.publish(self.model_file(net, schedule, state), net.clone());
    }
}

impl PixelObjective<'_> {
    /// The model file of `net` as it stands, `state` into `schedule`.
    fn model_file(&self, net: &NprtNet, schedule: &Schedule, state: &RunState) -> ModelFile {
        let transport_params = net.transport_params();
        let options = TrainOptions {
            schedule: schedule.clone(),
            ..self.opts.clone()
        };
        ModelFile {
            format: MODEL_FORMAT.into(),
            version: MODEL_VERSION,
            config: self.config.clone(),
            bounds: self.set.manifest.bounds,
            scene: self.set.manifest.settings.scene.clone(),
            scene_hash: self.set.manifest.settings.scene_hash.clone(),
            dataset_hash: self.set.dataset_hash.clone(),
            transport_params,
            encoder_params: net.num_params() - transport_params,
            training: serde_json::json!({
                "options": options,
                "epochs_done": state.epoch,
                "steps": state.step,
                "samples": state.samples,
                "seconds": state.seconds,
                "adam_epsilon": ADAM_EPSILON,
                "loss": self.opts.loss.name(),
                "targets": self.opts.targets.name(),
            }),
            level_gain: (self.opts.calibration == Calibration::Level)
                .then(|| level_gain(net, &self.set.train, LEVEL_SAMPLES, self.opts.batch_size)),
            weights_blake3: None,
        }
    }
}

/// The views of a group of batches, whose records are let go once the group is done: an
/// epoch then holds only a group's views in memory, however large the dataset.
struct GroupViews<'a>(Vec<&'a ViewSamples>);

impl Drop for GroupViews<'_> {
    fn drop(&mut self) {
        self.0.iter().for_each(|v| v.release());
    }
}

/// Trains (or resumes training of) the model in `out`; returns the run's summary and the
/// model's config as saved.
pub fn train(
    set: &TrainingSet,
    config: &ModelConfig,
    opts: &TrainOptions,
    out: &Path,
    engine: Engine,
    watch: Watch,
) -> Result<(TrainSummary, ModelFile)> {
    opts.check()?;
    // On the GPU the steps run on our own kernels, with the network's host copy (for saving)
    // on the CPU.
    let kernels = cfg!(feature = "gpu") && engine.is_gpu();
    if opts.precision != Precision::F32 && !kernels {
        bail!(
            "--precision {} trains on nprt's own GPU kernels only: use --device gpu (a build \
             with the `gpu` feature)",
            opts.precision
        );
    }
    let transfer = match opts.targets {
        Targets::Radiance => 0,
        Targets::Transfer => {
            let k = set.transfer(config)?;
            let bytes = opts.batch_size as u128 * 12 * k as u128;
            nprt_io::ensure_memory(bytes, "the transfer vectors of a batch")?;
            k
        }
    };
    let objective = PixelObjective {
        set,
        config,
        opts,
        saved: Mutex::new(None),
        kernels,
        transfer,
    };
    let summary = training_loop::train(&objective, &opts.schedule, out, watch)?;
    // The loop saves the model on every path that returns a summary.
    let file = objective
        .saved
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .context("training returned without saving the model")?;
    Ok((summary, file))
}
