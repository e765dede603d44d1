//! Training samples from a dataset folder: the 19 per-pixel inputs, the reference radiance and
//! the pre-processed, rotated map of every view.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Result};
use glam::Vec3;
use nprt_data::dataset::{load_manifest_hashed, Manifest, ViewRecord};
use nprt_scene::envmap::EnvMap;
use nprt_trace::GBuffer;
use rayon::prelude::*;

use crate::encoding::features::{gbuffer_features, FEATURES};
use crate::model::config::ModelConfig;
use crate::model::direct_light::DirectLight;
use crate::network::encoder::LightInput;

/// The foreground pixels of one view.
pub struct ViewSamples {
    /// [n, 19] inputs.
    pub features: Vec<f32>,
    /// [n, 3] the radiance the network learns: the reference's, or its indirect part for a
    /// model that traces direct light.
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

    /// Bytes its values take in memory.
    pub fn bytes(&self) -> usize {
        let floats = self.features.capacity() + self.radiance.capacity();
        (floats + self.light.pixels.capacity()) * std::mem::size_of::<f32>()
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
    /// Reads every view of the dataset in `dir` (in parallel) as the model `config` learns
    /// it: its map prepared for the encoder, and the radiance it must predict.
    pub fn load(dir: &Path, config: &ModelConfig) -> Result<Self> {
        let (manifest, dataset_hash) = load_manifest_hashed(dir)?;
        let width = config.encoder_width as u128;
        let most = manifest
            .views
            .iter()
            .map(|v| {
                let pixels = v.width as u128 * v.height as u128;
                pixels * (FEATURES as u128 + 3) * 4 + width * width / 2 * 3 * 4
            })
            .sum();
        nprt_io::ensure_memory(
            most,
            &format!(
                "loading the {} views of '{}' with encoder width {width}",
                manifest.views.len(),
                dir.display()
            ),
        )?;
        // Views grouped by their map, each map open only while its views load: a dataset with
        // a fresh map per view held all of them at once, 3.4 GB at the paper's size.
        let mut by_map: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for (i, v) in manifest.views.iter().enumerate() {
            by_map.entry(v.map).or_default().push(i);
        }
        let mut loaded: Vec<(usize, ViewSamples)> = by_map
            .into_par_iter()
            .map(|(m, views)| -> Result<Vec<(usize, ViewSamples)>> {
                let map = open_recorded_map(&manifest, m)?;
                views
                    .into_par_iter()
                    .map(|i| {
                        let samples = load_view(dir, &manifest, &map, &manifest.views[i], config)?;
                        Ok((i, samples))
                    })
                    .collect()
            })
            .collect::<Result<Vec<_>>>()?
            .into_iter()
            .flatten()
            .collect();
        loaded.sort_by_key(|(i, _)| *i);
        let (mut train, mut test) = (Vec::new(), Vec::new());
        for (i, samples) in loaded {
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
            train,
            test,
        })
    }

    /// Bytes the samples of every view take in memory.
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

/// One view's samples; `map` is the map it names.
fn load_view(
    dir: &Path,
    manifest: &Manifest,
    map: &EnvMap,
    view: &ViewRecord,
    config: &ModelConfig,
) -> Result<ViewSamples> {
    let image = nprt_data::views::load_view(dir, manifest, view)?;
    let light = LightInput::new(
        &view.light(map)?,
        0.0,
        config.encoder_width,
        config.map_norm,
    );
    Ok(view_samples(
        &image.gbuffer,
        &image.radiance,
        &image.direct,
        &manifest.bounds,
        light,
        config.direct,
    ))
}

/// The foreground pixels of a view (G-buffer `g`, reference `radiance` and its `direct` part)
/// as training samples under `light`, each with what the network learns of it (`mode`).
fn view_samples(
    g: &GBuffer,
    radiance: &[Vec3],
    direct: &[Vec3],
    bounds: &[[f32; 3]; 2],
    light: LightInput,
    mode: DirectLight,
) -> ViewSamples {
    // Sized exactly: grown by doubling, the samples of a paper-sized dataset (3000 views of
    // 256²) took 0.9 GB more (docs/model.md).
    let foreground = g.mask.iter().filter(|&&m| m > 0.5).count();
    let mut features = Vec::with_capacity(foreground * FEATURES);
    let mut target = Vec::with_capacity(foreground * 3);
    for i in (0..g.mask.len()).filter(|&i| g.mask[i] > 0.5) {
        features.extend(gbuffer_features(bounds, g, i));
        target.extend(mode.target(radiance[i], direct[i]).to_array());
    }
    ViewSamples {
        features,
        radiance: target,
        light,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use nprt_trace::GSample;

    #[test]
    fn a_model_that_traces_direct_light_learns_the_rest_of_the_foreground() {
        let mut g = GBuffer::default();
        for mask in [1.0, 0.0, 1.0] {
            g.push(GSample {
                normal: Vec3::Y,
                view: Vec3::Z,
                mask,
                ..GSample::default()
            });
        }
        let radiance = [Vec3::new(1.0, 2.0, 3.0), Vec3::splat(9.0), Vec3::splat(0.5)];
        // The last pixel's direct part exceeds its total by a rounding error.
        let direct = [
            Vec3::new(0.25, 0.5, 1.0),
            Vec3::splat(9.0),
            Vec3::splat(0.5000001),
        ];
        let map = EnvMap::constant(Vec3::ONE).unwrap();
        let samples = |mode| {
            let light = LightInput::new(&map, 0.0, 64, crate::MapNorm::Channel);
            view_samples(&g, &radiance, &direct, &[[-1.0; 3], [1.0; 3]], light, mode)
        };
        let learned = samples(DirectLight::Learned);
        assert_eq!(learned.radiance, [1.0, 2.0, 3.0, 0.5, 0.5, 0.5]);
        let traced = samples(DirectLight::Traced);
        assert_eq!(traced.radiance, [0.75, 1.5, 2.0, 0.0, 0.0, 0.0]);
        assert_eq!(traced.features, learned.features);
        assert_eq!(traced.len(), 2);
    }
}
