//! Deep Shading's training and test views as its steps take them: each view's feature image,
//! radiance and mask padded to multiples of 8 and its map's encoder input, batched into the
//! CPU engine's [`UnetBatch`] (which the GPU kernels take too).

use anyhow::{bail, Result};
use nprt_data::views::ImageView;
use nprt_scene::EnvMap;

use super::unet::feature_image;
use crate::cpu::UnetBatch;
use crate::encoding::map_norm::MapNorm;
use crate::loss::Loss;
use crate::network::encoder::LightInput;
use crate::network::unet::DeepShading;
use crate::training::training_set::log_mean_level;

/// What training needs of each view, padded to multiples of 8.
pub(super) struct Sample {
    features: Vec<f32>,
    radiance: Vec<f32>,
    mask: Vec<f32>,
    light: LightInput,
    foreground: u64,
}

/// Views of one split, all of one padded size.
pub(super) struct Split {
    pub samples: Vec<Sample>,
    width: usize,
    height: usize,
}

impl Split {
    /// ln of the mean foreground radiance relative to its map's mean (as
    /// `TrainingSet::log_relative_level`).
    pub fn log_relative_level(&self) -> f32 {
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

    pub fn new(
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
    pub fn batch(&self, batch: &[usize]) -> (UnetBatch, u64) {
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
    pub fn loss(
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
