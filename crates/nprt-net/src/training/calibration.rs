//! Output calibration: a gain per channel that gives a trained network's radiance the level of
//! its training targets.
//!
//! The paper's loss, L1 on log(1 + x), is minimised by the median of what the network cannot
//! tell apart, below the mean for right-skewed radiance (a sun patch it cannot yet place, a
//! rare bright path in a noisy target). Regression in log space has the same bias in
//! statistics, where the classic correction (Duan's smearing estimate, 1983) multiplies the
//! back-transformed prediction by a factor measured on the training residuals. This is that
//! factor per channel: the training targets' sum over the network's. The mean of noisy
//! targets is unbiased, so no converged reference is needed, and no held-out view is seen.

use crate::choice::named_choice;
use crate::model::folder::LEVEL_GAIN_RANGE;
use crate::network::nprt_net::NprtNet;
use crate::training::batch::Batch;
use crate::training::training_set::ViewSamples;

/// Whether a trained model's radiance is calibrated to its training targets' level.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Calibration {
    /// The network's output as it is (the paper). Models saved before the choice existed.
    #[default]
    None,
    /// Each channel multiplied by [`level_gain`], measured whenever the model is saved.
    Level,
}

named_choice!(Calibration, "calibration", {
    None => "none",
    Level => "level",
});

/// Training pixels the level gain is measured on: its standard error on the demo is far below
/// the darkness it corrects, for the time of one validation pass.
pub const LEVEL_SAMPLES: usize = 65_536;

/// Per channel, the sum of the targets over the sum of `net`'s predictions on a fixed, evenly
/// strided subset of at most `max_samples` of `views`' pixels, each pixel relative to its map's
/// scale so that every lighting counts alike. 1 for a channel whose targets or predictions hold
/// no light, or whose gain would leave [`LEVEL_GAIN_RANGE`] (a network a thousandfold off is
/// not one a gain corrects): a degenerate dataset keeps the network's output.
pub fn level_gain(
    net: &NprtNet,
    views: &[ViewSamples],
    max_samples: usize,
    batch_size: usize,
) -> [f32; 3] {
    let views: Vec<&ViewSamples> = views.iter().filter(|v| !v.is_empty()).collect();
    let (mut predicted, mut target) = ([0.0f64; 3], [0.0f64; 3]);
    for batch in Batch::strided(&views, max_samples, batch_size) {
        let pred = crate::cpu::predict(net, &batch.samples());
        for (i, s) in batch.scale.chunks_exact(3).enumerate() {
            for k in 0..3 {
                predicted[k] += (pred[3 * i + k] / s[k]) as f64;
                target[k] += (batch.radiance[3 * i + k] / s[k]) as f64;
            }
        }
    }
    views.iter().for_each(|v| v.release());
    std::array::from_fn(|k| {
        let gain = (target[k] / predicted[k]) as f32;
        match LEVEL_GAIN_RANGE.contains(&gain) {
            true => gain,
            false => 1.0,
        }
    })
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::encoding::map_norm::MapNorm;
    use crate::init::Init;
    use crate::model::config::ModelConfig;
    use crate::network::design::Design;
    use crate::network::encoder::LightInput;
    use glam::Vec3;
    use nprt_data::dataset::{PackedDataset, PackedPixel, PackedTarget};
    use nprt_scene::envmap::EnvMap;
    use nprt_trace::GSample;

    #[test]
    fn the_gain_is_the_factor_between_targets_and_predictions() {
        let config = ModelConfig {
            encoder_width: 64,
            ..ModelConfig::new(Design::Albedo, None)
        };
        let net = config.build(&mut Init::new(1));
        let sky = nprt_scene::open_envmap("builtin:sky").unwrap();
        let warm = EnvMap::constant(Vec3::new(3.0, 1.0, 0.2)).unwrap();
        let bounds = [[-1.0; 3], [1.0; 3]];
        // Two views under maps of very different scales, with pseudo-random inputs.
        let sizes = [200, 57];
        let value = |i: usize, v: usize| ((i * 7919 + v * 104_729) % 2001) as f32 / 1000.0 - 1.0;
        let records = |radiance: &dyn Fn(usize, usize) -> Vec3| -> Vec<Vec<PackedPixel>> {
            (0..2)
                .map(|v| {
                    (0..sizes[v])
                        .map(|p| {
                            let f = |k: usize| value(7 * p + k, v);
                            let s = GSample {
                                position: Vec3::new(f(0), f(1), f(2)),
                                normal: Vec3::new(f(3), f(4), 0.5).normalize(),
                                view: Vec3::new(f(5), 0.5, f(6)).normalize(),
                                kd: Vec3::splat(f(0).abs()),
                                ks: Vec3::splat(f(1).abs()),
                                alpha: f(2).abs(),
                                mask: 1.0,
                            };
                            PackedPixel::encode(&s, radiance(v, p), &bounds)
                        })
                        .collect()
                })
                .collect()
        };
        let views = |records: Vec<Vec<PackedPixel>>| -> Vec<ViewSamples> {
            let pack = Arc::new(PackedDataset::from_records(
                bounds,
                PackedTarget::Radiance,
                records,
            ));
            [&sky, &warm]
                .into_iter()
                .enumerate()
                .map(|(v, map)| {
                    let light = LightInput::new(map, 40.0 * v as f32, 64, MapNorm::Channel);
                    ViewSamples::new(pack.clone(), v, light)
                })
                .collect()
        };
        let dark = views(records(&|_, _| Vec3::ZERO));
        // Targets that are exactly the network's predictions times a known factor per channel.
        let factor = [1.3f32, 0.7, 2.0];
        let predictions: Vec<Vec<f32>> = dark
            .iter()
            .map(|view| {
                let all: Vec<(u32, u32)> = (0..view.len() as u32).map(|p| (0, p)).collect();
                crate::cpu::predict(&net, &Batch::gather(&[view], &all, 0).samples())
            })
            .collect();
        let scaled = views(records(&|v, p| {
            Vec3::from_array(std::array::from_fn(|k| {
                predictions[v][3 * p + k] * factor[k]
            }))
        }));
        // Over every pixel, and over a strided subset in small batches.
        for (max_samples, batch_size) in [(1000, 1000), (50, 16)] {
            let gain = level_gain(&net, &scaled, max_samples, batch_size);
            for k in 0..3 {
                assert!(
                    (gain[k] / factor[k] - 1.0).abs() < 1e-4,
                    "{gain:?} against {factor:?}"
                );
            }
        }
        // Targets without light: the network's output is kept, not zeroed.
        assert_eq!(level_gain(&net, &dark, 1000, 1000), [1.0; 3]);
    }
}
