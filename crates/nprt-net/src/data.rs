//! Training samples from a dataset folder: the 19 per-pixel inputs, the reference radiance and
//! the pre-processed, rotated map of every view.

use std::path::Path;

use anyhow::{bail, Result};
use nprt_data::dataset::{load_manifest_hashed, Manifest, ViewRecord};
use nprt_scene::envmap::EnvMap;
use rayon::prelude::*;

use crate::encoder::LightInput;
use crate::features::gbuffer_features;
use crate::map_norm::MapNorm;

/// The foreground pixels of one view.
pub struct ViewSamples {
    /// [n, 19] inputs.
    pub features: Vec<f32>,
    /// [n, 3] reference radiance.
    pub radiance: Vec<f32>,
    /// The view's map, rotated and pre-processed for the encoder.
    pub light: LightInput,
}

impl ViewSamples {
    pub fn len(&self) -> usize {
        self.radiance.len() / 3
    }

    pub fn is_empty(&self) -> bool {
        self.radiance.is_empty()
    }
}

/// A dataset loaded for training: train and test views, and what identifies it.
pub struct TrainingSet {
    pub manifest: Manifest,
    /// BLAKE3 of manifest.json: a model records which dataset it was trained on.
    pub dataset_hash: String,
    pub train: Vec<ViewSamples>,
    pub test: Vec<ViewSamples>,
}

impl TrainingSet {
    /// Reads every view of the dataset in `dir` (in parallel) and prepares its map for an
    /// encoder of input width `encoder_width`, normalised by `norm`.
    pub fn load(dir: &Path, encoder_width: usize, norm: MapNorm) -> Result<Self> {
        let (manifest, dataset_hash) = load_manifest_hashed(dir)?;
        let maps = open_recorded_maps(&manifest)?;
        let load = |split: &str| -> Result<Vec<ViewSamples>> {
            manifest
                .views
                .par_iter()
                .filter(|v| v.split == split)
                .map(|v| load_view(dir, &manifest, &maps, v, encoder_width, norm))
                .collect()
        };
        let train = load("train")?;
        let test = load("test")?;
        if train.iter().all(|v| v.is_empty()) {
            bail!(
                "dataset '{}' has no foreground pixel in its training views",
                dir.display()
            );
        }
        Ok(TrainingSet {
            manifest,
            dataset_hash,
            train,
            test,
        })
    }

    /// ln of the mean training radiance relative to its map's scale (what the networks
    /// predict before the scale), over every foreground pixel and channel.
    pub fn log_relative_level(&self) -> f32 {
        let (mut sum, mut n) = (0.0f64, 0usize);
        for v in &self.train {
            sum += relative_radiance(&v.radiance, v.light.scale);
            n += v.radiance.len();
        }
        log_mean_level(sum, n)
    }
}

/// ln of the mean of `count` relative radiance values summing to `sum`, kept finite for data
/// without light.
pub(crate) fn log_mean_level(sum: f64, count: usize) -> f32 {
    ((sum / count.max(1) as f64).max(1e-12) as f32).ln()
}

/// The sum of `radiance` ([n, 3], negative values as zero) divided channel by channel by
/// `scale`.
fn relative_radiance(radiance: &[f32], scale: [f32; 3]) -> f64 {
    radiance
        .chunks_exact(3)
        .map(|c| {
            (0..3)
                .map(|k| c[k].max(0.0) as f64 / scale[k] as f64)
                .sum::<f64>()
        })
        .sum()
}

/// Opens the dataset's maps and checks each is the one the dataset was rendered with.
pub fn open_recorded_maps(manifest: &Manifest) -> Result<Vec<EnvMap>> {
    manifest
        .settings
        .envmaps
        .iter()
        .map(|rec| {
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
        })
        .collect()
}

fn load_view(
    dir: &Path,
    manifest: &Manifest,
    maps: &[EnvMap],
    view: &ViewRecord,
    encoder_width: usize,
    norm: MapNorm,
) -> Result<ViewSamples> {
    let image = nprt_data::views::load_view(dir, manifest, view)?;
    let g = &image.gbuffer;
    let mut features = Vec::new();
    let mut radiance = Vec::new();
    for i in (0..g.mask.len()).filter(|&i| g.mask[i] > 0.5) {
        features.extend(gbuffer_features(&manifest.bounds, g, i));
        radiance.extend(image.radiance[i].to_array());
    }
    Ok(ViewSamples {
        features,
        radiance,
        light: LightInput::new(&view.lighting(maps)?, 0.0, encoder_width, norm),
    })
}
