//! Training the Deep Shading U-Net on a dataset folder: whole training views per step, the
//! masked log-L1 loss, validation on the test views.

use std::path::Path;

use anyhow::{bail, Result};
use nprt_data::dataset::load_manifest_hashed;
use nprt_data::views::{load_views, ImageView};
use nprt_scene::EnvMap;
use rand::seq::SliceRandom;

use super::model::{read_file, DeepShadingFile, CONFIG_FILE, TAG};
use super::options::DeepShadingOptions;
use super::unet::feature_image;
use crate::cpu::UnetBatch;
use crate::encoding::map_norm::MapNorm;
use crate::init::Init;
use crate::loss::Loss;
use crate::model::folder::{save_weights, WEIGHTS_FILE};
use crate::network::encoder::{check_input_width, LightInput};
use crate::network::parameters::Parameters;
use crate::network::unet::DeepShading;
use crate::optimiser::EngineSteps;
use crate::training::checkpoint::{self, RunState};
use crate::training::host_steps::HostSteps;
use crate::training::schedule::Schedule;
use crate::training::training_loop::{self, epoch_rng, Objective, Steps, TrainSummary, Watch};
use crate::training::training_set::{log_mean_level, open_recorded_maps};

/// What training needs of each view, padded to multiples of 8.
struct Sample {
    features: Vec<f32>,
    radiance: Vec<f32>,
    mask: Vec<f32>,
    light: LightInput,
    foreground: u64,
}

/// Views of one split, all of one padded size.
struct Split {
    samples: Vec<Sample>,
    width: usize,
    height: usize,
}

impl Split {
    /// ln of the mean foreground radiance relative to its map's mean (as
    /// `TrainingSet::log_relative_level`).
    fn log_relative_level(&self) -> f32 {
        let (mut sum, mut n) = (0.0f64, 0usize);
        for s in &self.samples {
            // Background pixels hold zero radiance here; channels are planes of `plane` values.
            let plane = s.radiance.len() / 3;
            sum += (0..3)
                .map(|k| {
                    let fg: f64 = s.radiance[k * plane..(k + 1) * plane]
                        .iter()
                        .map(|&r| r.max(0.0) as f64)
                        .sum();
                    fg / s.light.scale[k] as f64
                })
                .sum::<f64>();
            n += 3 * s.foreground as usize;
        }
        log_mean_level(sum, n)
    }

    fn new(
        views: &[ImageView],
        maps: &[EnvMap],
        bounds: &[[f32; 3]; 2],
        encoder_width: usize,
        norm: MapNorm,
    ) -> Result<Self> {
        let Some(first) = views.first() else {
            return Ok(Split {
                samples: Vec::new(),
                width: 0,
                height: 0,
            });
        };
        let (w, h) = (first.width, first.height);
        if views.iter().any(|v| (v.width, v.height) != (w, h)) {
            bail!("Deep Shading trains on views of one resolution per split");
        }
        let samples = views
            .iter()
            .map(|v| {
                let (features, pw, ph) = feature_image(bounds, &v.gbuffer, w, h);
                let mut radiance = vec![0.0; 3 * pw * ph];
                let mut mask = vec![0.0; pw * ph];
                for i in 0..w * h {
                    let j = (i / w) * pw + i % w;
                    mask[j] = v.gbuffer.mask[i];
                    for c in 0..3 {
                        radiance[c * pw * ph + j] = v.radiance[i][c] * mask[j];
                    }
                }
                Ok(Sample {
                    foreground: mask.iter().filter(|&&m| m > 0.5).count() as u64,
                    features,
                    radiance,
                    mask,
                    light: LightInput::new(&v.record.lighting(maps)?, 0.0, encoder_width, norm),
                })
            })
            .collect::<Result<_>>()?;
        Ok(Split {
            samples,
            width: w.div_ceil(8) * 8,
            height: h.div_ceil(8) * 8,
        })
    }

    /// The views `batch` as the CPU engine takes them, and their foreground pixels.
    fn batch(&self, batch: &[usize]) -> (UnetBatch, u64) {
        let views: Vec<&Sample> = batch.iter().map(|&i| &self.samples[i]).collect();
        let cat = |f: fn(&Sample) -> &[f32]| -> Vec<f32> {
            views.iter().flat_map(|s| f(s).iter().copied()).collect()
        };
        let unet = UnetBatch {
            features: cat(|s| &s.features),
            radiance: cat(|s| &s.radiance),
            mask: cat(|s| &s.mask),
            lights: cat(|s| &s.light.pixels),
            light_width: views[0].light.width,
            scale: cat(|s| &s.light.scale),
            height: self.height,
            width: self.width,
        };
        (unet, views.iter().map(|s| s.foreground).sum())
    }

    /// The masked log-L1 loss of the views `batch` and, when `train`, its gradients.
    fn loss(
        &self,
        net: &DeepShading,
        batch: &[usize],
        train: bool,
    ) -> (f64, Option<DeepShading>, u64) {
        let (unet, foreground) = self.batch(batch);
        let (loss, grads) = net.loss_and_gradients(&unet, Loss::LogL1, train);
        (loss, grads, foreground)
    }
}

struct UnetObjective {
    train: Split,
    test: Split,
    /// The model file as it will be saved, less what `save_model` fills in from the network
    /// and the run (parameter counts, progress).
    file: DeepShadingFile,
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
        save_weights(&out.join(WEIGHTS_FILE), net, TAG)?;
        let mut file = self.file.clone();
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
/// summary and the model's config as saved; `watch` hears each epoch's end. The U-Net trains on the CPU engine whatever the
/// device: the GPU kernels do not have its up-sampling and skip connections yet.
pub fn train(
    data: &Path,
    opts: &DeepShadingOptions,
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
    };
    let objective = UnetObjective { train, test, file };
    let summary = training_loop::train(&objective, &opts.schedule, out, watch)?;
    Ok((summary, read_file(out)?))
}
