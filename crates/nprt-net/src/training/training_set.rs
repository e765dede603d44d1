//! Training samples from a dataset folder: the 19 per-pixel inputs, the reference radiance and
//! the pre-processed, rotated map of every view.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use anyhow::{bail, Result};
use nprt_data::dataset::{load_manifest_hashed, Manifest, PackedDataset, PackedPixel};
use nprt_scene::envmap::EnvMap;
use rayon::prelude::*;

use crate::encoding::features::{sample_features, FEATURES};
use crate::model::config::{ModelConfig, TRAINING_COPIES};
use crate::network::encoder::LightInput;

/// The foreground pixels of one view: its records in the dataset's pack and its map.
pub struct ViewSamples {
    pack: Arc<PackedDataset>,
    /// The view's position in the manifest.
    view: usize,
    /// The view's map, rotated and pre-processed for the encoder.
    pub light: LightInput,
}

impl ViewSamples {
    /// View `view` of `pack` under `light`.
    pub fn new(pack: Arc<PackedDataset>, view: usize, light: LightInput) -> Self {
        ViewSamples { pack, view, light }
    }

    pub fn len(&self) -> usize {
        self.pixels().len()
    }

    pub fn is_empty(&self) -> bool {
        self.pixels().is_empty()
    }

    pub fn pixels(&self) -> &[PackedPixel] {
        self.pack.view(self.view)
    }

    /// The index in the pack of the view's first record (its pixel p's is this plus p).
    pub fn first_record(&self) -> u64 {
        self.pack.header().views[self.view][0]
    }

    /// Pixel `p`'s 19 network inputs and the radiance the network learns there.
    pub fn sample(&self, p: usize) -> ([f32; FEATURES], [f32; 3]) {
        let bounds = &self.pack.header().bounds;
        let (s, radiance) = self.pixels()[p].decode(bounds);
        (sample_features(bounds, &s), radiance.to_array())
    }

    /// Appends pixel `p`'s first `coefficients` transfer coefficients (R G B each) to `out`;
    /// zeros where the pack holds none (refused before training: [`TrainingSet::transfer`]).
    pub fn transfer_into(&self, p: usize, coefficients: usize, out: &mut Vec<f32>) {
        match self.pack.transfer(self.view) {
            Some(t) => out.extend(t.vector(p, coefficients)),
            None => out.resize(out.len() + 3 * coefficients, 0.0),
        }
    }

    /// Lets go of the view's records in memory until they are read again.
    pub fn release(&self) {
        self.pack.release(self.view);
    }

    /// Bytes the view's map takes in memory (its records are mapped from the pack).
    pub fn bytes(&self) -> usize {
        self.light.pixels.capacity() * std::mem::size_of::<f32>()
    }
}

/// A dataset loaded for training: its pack (made at first use), the train and test views, and
/// what identifies it.
pub struct TrainingSet {
    pub manifest: Manifest,
    /// BLAKE3 of manifest.json: a model records which dataset it was trained on.
    pub dataset_hash: String,
    pub pack: Arc<PackedDataset>,
    pub train: Vec<ViewSamples>,
    pub test: Vec<ViewSamples>,
}

impl TrainingSet {
    /// Opens the dataset in `dir` as the model `config` learns it: the pack of the radiance it
    /// must predict (packed first where missing or out of date, with a bar if `progress`, saying
    /// why through `on_pack`) and each view's map prepared for the encoder.
    pub fn load(
        dir: &Path,
        config: &ModelConfig,
        progress: bool,
        on_pack: impl Fn(&str),
    ) -> Result<Self> {
        let (manifest, dataset_hash) = load_manifest_hashed(dir)?;
        config.ensure_memory(TRAINING_COPIES, "training the network")?;
        let width = config.encoder_width as u128;
        nprt_io::ensure_memory(
            manifest.views.len() as u128 * (width * width / 2 * 3 * 4),
            &format!(
                "the maps of the {} views of '{}' with encoder width {width}",
                manifest.views.len(),
                dir.display()
            ),
        )?;
        let pack = Arc::new(PackedDataset::open_or_pack(
            dir,
            &manifest,
            &dataset_hash,
            config.direct.packed_target(),
            progress,
            on_pack,
        )?);
        let lights = light_inputs(&manifest, config)?;
        let (mut train, mut test) = (Vec::new(), Vec::new());
        for (i, light) in lights {
            let samples = ViewSamples::new(pack.clone(), i, light);
            match manifest.views[i].split.as_str() {
                "train" => train.push(samples),
                _ => test.push(samples),
            }
        }
        if train.iter().all(|v| v.is_empty()) {
            bail!(
                "dataset '{}' has no foreground pixel in its training views",
                dir.display()
            );
        }
        Ok(TrainingSet {
            manifest,
            dataset_hash,
            pack,
            train,
            test,
        })
    }

    /// The coefficients per channel a model with `config` learns of this set's transfer
    /// vectors: its SH basis', which the dataset must hold (`nprt generate --transfer sh:L`,
    /// L at least the model's band).
    pub fn transfer(&self, config: &ModelConfig) -> Result<usize> {
        let scene = &self.manifest.settings.scene;
        let Some(band) = config.transfer_band() else {
            bail!(
                "--targets transfer trains the linear design on an SH basis (--arch linear \
                 --basis sh:L, or another design whose every track is linear in the lighting), \
                 whose coefficients the transfer vectors are; this is {}",
                config.label()
            )
        };
        match self.manifest.settings.transfer {
            Some(t) if t.band as usize >= band => Ok(config.light_basis().size()),
            Some(t) => bail!(
                "the dataset's transfer vectors are {t}, fewer bands than the model's sh:{band}: \
                 train with --basis sh:{} or lower, or generate with --transfer sh:{band}",
                t.band
            ),
            None => bail!(
                "the dataset (of {scene}) holds no transfer vectors: generate it with --transfer \
                 sh:{band} to train on them"
            ),
        }
    }

    /// Bytes the views' maps take in memory.
    pub fn bytes(&self) -> usize {
        self.train
            .iter()
            .chain(&self.test)
            .map(ViewSamples::bytes)
            .sum()
    }

    /// ln of the mean training radiance relative to its map's scale (what the networks
    /// predict before the scale), over every foreground pixel and channel.
    pub fn log_relative_level(&self) -> f32 {
        let (mut sum, mut n) = (0.0f64, 0usize);
        for v in &self.train {
            sum += relative_radiance(v.pixels().iter().map(|p| p.radiance), v.light.scale);
            n += 3 * v.len();
            v.release();
        }
        log_mean_level(sum, n)
    }
}

/// ln of the mean of `count` relative radiance values summing to `sum`, kept finite for data
/// without light.
pub(crate) fn log_mean_level(sum: f64, count: usize) -> f32 {
    ((sum / count.max(1) as f64).max(1e-12) as f32).ln()
}

/// The sum of `radiance` (negative values as zero) divided channel by channel by `scale`.
fn relative_radiance(radiance: impl Iterator<Item = [f32; 3]>, scale: [f32; 3]) -> f64 {
    radiance
        .map(|c| {
            (0..3)
                .map(|k| c[k].max(0.0) as f64 / scale[k] as f64)
                .sum::<f64>()
        })
        .sum()
}

/// Opens the dataset's maps and checks each is the one the dataset was rendered with.
pub fn open_recorded_maps(manifest: &Manifest) -> Result<Vec<EnvMap>> {
    (0..manifest.settings.envmaps.len())
        .map(|m| open_recorded_map(manifest, m))
        .collect()
}

/// Opens the dataset's map `index` and checks it is the one the dataset was rendered with.
pub fn open_recorded_map(manifest: &Manifest, index: usize) -> Result<EnvMap> {
    let Some(rec) = manifest.settings.envmaps.get(index) else {
        bail!(
            "a view names map {index}, but the dataset records {} maps",
            manifest.settings.envmaps.len()
        );
    };
    let hash = nprt_data::lighting::map_hash(&rec.spec)?;
    if hash != rec.hash {
        bail!(
            "environment map '{}' differs from the one the dataset was rendered with (hash {} ≠ {})",
            rec.spec,
            &hash[..12],
            &rec.hash[..12.min(rec.hash.len())]
        );
    }
    nprt_scene::open_envmap(&rec.spec)
}

/// Each view's light input for `config`'s encoder, in view order. Views are grouped by their
/// map, each map open only while its views' inputs are made: a dataset with a fresh map per
/// view held all of them at once, 3.4 GB at the paper's size.
fn light_inputs(manifest: &Manifest, config: &ModelConfig) -> Result<Vec<(usize, LightInput)>> {
    let mut by_map: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (i, v) in manifest.views.iter().enumerate() {
        by_map.entry(v.map).or_default().push(i);
    }
    // Views that mix maps (`nprt generate --mix-maps`) need several at once: the training
    // maps, a folder's few, are then all opened once.
    let mixing = manifest.views.iter().any(|v| !v.mix.is_empty());
    let all = mixing.then(|| open_recorded_maps(manifest)).transpose()?;
    let mut lights: Vec<(usize, LightInput)> = by_map
        .into_par_iter()
        .map(|(m, views)| -> Result<Vec<(usize, LightInput)>> {
            let map = match all.as_ref().and_then(|maps| maps.get(m)) {
                Some(map) => map.clone(),
                None => open_recorded_map(manifest, m)?,
            };
            views
                .into_par_iter()
                .map(|i| {
                    let v = &manifest.views[i];
                    let lighting = match &all {
                        Some(maps) => v.lighting(maps)?,
                        None => v.light(&map)?,
                    };
                    Ok((i, config.light_input(&lighting, 0.0)))
                })
                .collect()
        })
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect();
    lights.sort_by_key(|(i, _)| *i);
    Ok(lights)
}
