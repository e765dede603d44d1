//! Training the Deep Shading U-Net on a dataset folder: whole training views per step, the
//! masked log-L1 loss, validation on the test views.

use std::path::Path;

use anyhow::{bail, Result};
use nprt_data::dataset::load_manifest_hashed;
use nprt_data::views::load_views;
use rand::seq::SliceRandom;

use super::model::{read_file, DeepShadingFile, CONFIG_FILE, TAG};
use super::options::DeepShadingOptions;
use super::split::Split;
use crate::engine::Engine;
use crate::init::Init;
use crate::model::folder::{save_weights, WEIGHTS_FILE};
use crate::network::encoder::check_input_width;
use crate::network::unet::DeepShading;
use crate::optimiser::EngineSteps;
use crate::parameters::Parameters;
use crate::training::checkpoint::{self, RunState};
use crate::training::host_steps::HostSteps;
use crate::training::schedule::Schedule;
use crate::training::training_loop::{self, epoch_rng, Objective, Steps, TrainSummary, Watch};
use crate::training::training_set::open_recorded_maps;

struct UnetObjective {
    train: Split,
    test: Split,
    /// The model file as it will be saved, less what `save_model` fills in from the network
    /// and the run (parameter counts, progress).
    file: DeepShadingFile,
    /// Whether the steps run on our own GPU kernels.
    #[cfg_attr(not(feature = "gpu"), allow(dead_code))]
    kernels: bool,
}

impl Objective for UnetObjective {
    type Net = DeepShading;
    type Batch = Vec<usize>;

    fn tag(&self) -> String {
        TAG.into()
    }

    fn title(&self) -> String {
        "Deep Shading (U-Net)".into()
    }

    fn run_key(&self) -> serde_json::Value {
        serde_json::json!({
            "network": TAG,
            "dataset_hash": self.file.dataset_hash,
            "batch_views": self.file.options.batch_views,
            "encoder_width": self.file.encoder_width,
            "map_norm": self.file.options.map_norm,
        })
    }

    fn build(&self, init: &mut Init) -> DeepShading {
        DeepShading::new(init, self.file.encoder_width)
            .shift_output_level(self.train.log_relative_level())
    }

    fn steps(&self, _seed: u64, _epoch: usize) -> usize {
        self.train
            .samples
            .len()
            .div_ceil(self.file.options.batch_views)
    }

    fn batches(&self, seed: u64, epoch: usize, from: usize) -> impl Iterator<Item = Vec<usize>> {
        let mut order: Vec<usize> = (0..self.train.samples.len()).collect();
        order.shuffle(&mut epoch_rng(seed, epoch as u64, 0));
        order
            .chunks(self.file.options.batch_views)
            .skip(from)
            .map(<[usize]>::to_vec)
            .collect::<Vec<_>>()
            .into_iter()
    }

    fn engine_steps(&self, net: &DeepShading) -> Result<Steps<'_, Self>> {
        #[cfg(feature = "gpu")]
        if self.kernels {
            let steps = super::kernel_steps::UnetKernelSteps::new(net, &self.train, &self.test)?;
            return Ok(Box::new(steps));
        }
        Ok(Box::new(HostSteps::new(
            net,
            |net: &DeepShading, batch: &Vec<usize>| {
                let (loss, grads, samples) = self.train.loss(net, batch, true);
                (loss, grads.expect("asked for"), samples)
            },
            |net: &DeepShading, batch: &Vec<usize>| self.test.loss(net, batch, false).0,
        )))
    }

    fn validation_loss(&self, steps: &mut dyn EngineSteps<DeepShading, Vec<usize>>) -> Result<f64> {
        let n = self.test.samples.len();
        let views: Vec<usize> = (0..n).collect();
        let mut sum = 0.0;
        for chunk in views.chunks(self.file.options.batch_views) {
            sum += steps.loss(&chunk.to_vec())? * chunk.len() as f64;
        }
        Ok(sum / n as f64)
    }

    fn model_files(&self) -> [&'static str; 2] {
        [CONFIG_FILE, WEIGHTS_FILE]
    }

    fn save_model(
        &self,
        out: &Path,
        net: &DeepShading,
        schedule: &Schedule,
        state: &RunState,
    ) -> Result<()> {
        let hash = save_weights(&out.join(WEIGHTS_FILE), net, TAG)?;
        let mut file = self.file.clone();
        file.weights_blake3 = Some(hash);
        file.options.schedule = schedule.clone();
        file.unet_params = net.unet_params();
        file.encoder_params = net.light.num_params();
        file.epochs_done = state.epoch;
        file.seconds = state.seconds;
        nprt_io::write_file(&out.join(CONFIG_FILE), serde_json::to_vec_pretty(&file)?)
    }
}

/// Trains (or resumes exactly, Adam's moments included) a Deep Shading network on the dataset
/// in `data`, with the validation loss on its test views after every epoch. Returns the run's
/// summary and the model's config as saved; `watch` hears each epoch's end. The steps run on
/// `engine`; a checkpoint resumes on either.
pub fn train(
    data: &Path,
    opts: &DeepShadingOptions,
    engine: Engine,
    out: &Path,
    watch: Watch,
) -> Result<(TrainSummary, DeepShadingFile)> {
    opts.schedule.check()?;
    check_input_width(opts.encoder_width)?;
    if opts.batch_views == 0 {
        bail!("the views per Deep Shading step must be positive");
    }
    if out.join(CONFIG_FILE).exists() && !checkpoint::exists(out) {
        bail!(
            "'{}' holds a Deep Shading model without a checkpoint (from an older nprt); choose another folder or delete it",
            out.display()
        );
    }
    let (manifest, dataset_hash) = load_manifest_hashed(data)?;
    let maps = open_recorded_maps(&manifest)?;
    let split = |name: &str| -> Result<Split> {
        let views = load_views(data, &manifest, name)?;
        Split::new(
            &views,
            &maps,
            &manifest.bounds,
            opts.encoder_width,
            opts.map_norm,
        )
    };
    let train = split("train")?;
    if train.samples.is_empty() {
        bail!("dataset '{}' has no training views", data.display());
    }
    let test = split("test")?;
    let s = &manifest.settings;
    let file = DeepShadingFile {
        format: TAG.into(),
        version: 1,
        encoder_width: opts.encoder_width,
        bounds: manifest.bounds,
        scene: s.scene.clone(),
        scene_hash: s.scene_hash.clone(),
        dataset_hash,
        unet_params: 0,
        encoder_params: 0,
        options: opts.clone(),
        epochs_done: 0,
        seconds: 0.0,
        weights_blake3: None,
    };
    let objective = UnetObjective {
        train,
        test,
        file,
        kernels: cfg!(feature = "gpu") && engine.is_gpu(),
    };
    let summary = training_loop::train(&objective, &opts.schedule, out, watch)?;
    Ok((summary, read_file(out)?))
}
