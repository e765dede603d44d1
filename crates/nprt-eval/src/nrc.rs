//! The Neural Radiance Cache baseline (Müller, Rousselle, Novák, Keller 2021; the paper's Table
//! 6): frames path-traced with a radiance cache read where paths end (nprt-trace's cached
//! paths), the cache (nprt-net's `RadianceCache`, on the CPU engine or the GPU kernels) trained
//! online from each
//! frame's training paths, frame after frame. NRC reads it where the area-spread heuristic ends
//! a path; NRC-CACHE at the first vertex, where nprt's networks work. It needs no
//! precomputation, so it starts cold and lags changes of view and light: what the temporal
//! evaluation measures. docs/evaluation.md lists where it departs from Müller et al.

use anyhow::Result;
use glam::Vec3;
use nprt_net::network::radiance_cache::{CacheQuery, RadianceCache};
use nprt_net::training::cache_trainer::CacheTrainer;
use nprt_net::{position_frame, Engine, Init};
use nprt_scene::{Camera, EnvMap};
use nprt_trace::{
    pixel_rng, trace_cached, CachePath, CacheRead, CacheVertex, CachedPath, CameraRay,
    PathSettings, TraceScene,
};
use rand::seq::SliceRandom;
use rand::RngExt;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How the cache renders and trains.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct NrcSettings {
    #[serde(skip, default = "spread")]
    pub read: CacheRead,
    /// Rendering paths per pixel.
    pub spp: u32,
    /// Share of the pixels that also trace a training path each frame.
    pub train_share: f32,
    /// Share of the training paths that never read the cache (Müller et al.: a sixteenth).
    pub unbiased_share: f32,
    /// Adam steps per frame, and the training pairs each takes.
    pub steps: usize,
    pub batch: usize,
    pub learning_rate: f64,
}

fn spread() -> CacheRead {
    CacheRead::Spread
}

impl NrcSettings {
    /// The settings nprt evaluates NRC (or, with `CacheRead::FirstVertex`, NRC-CACHE) at.
    pub fn new(read: CacheRead) -> Self {
        NrcSettings {
            read,
            spp: 1,
            train_share: 0.25,
            unbiased_share: 1.0 / 16.0,
            steps: 4,
            batch: 4096,
            learning_rate: 5e-3,
        }
    }
}

/// The Adam steps per frame that fit a cache's frame into `budget_ms`, from one frame's
/// rendering time (`render_ms`, reads included) and one step's (`step_ms`): at least one, at
/// most 16 (four times Müller et al.'s).
pub fn steps_within(budget_ms: f64, render_ms: f64, step_ms: f64) -> usize {
    (((budget_ms - render_ms) / step_ms.max(1e-6)).floor() as i64).clamp(1, 16) as usize
}

/// A cache rendering frame after frame, trained as it goes.
pub struct Nrc {
    trainer: CacheTrainer,
    settings: NrcSettings,
    /// How positions are normalised (the scene's bounds).
    frame_of: (Vec3, Vec3),
    seed: u64,
    frames: u64,
}

impl Nrc {
    /// A cold cache for a scene of `bounds`, trained on `engine`; every random choice follows
    /// `seed`.
    pub fn new(
        settings: NrcSettings,
        bounds: &[[f32; 3]; 2],
        seed: u64,
        engine: Engine,
    ) -> Result<Self> {
        let cache = RadianceCache::new(&mut Init::new(seed));
        Ok(Nrc {
            trainer: CacheTrainer::new(cache, settings.learning_rate, engine)?,
            settings,
            frame_of: position_frame(bounds),
            seed,
            frames: 0,
        })
    }

    fn query(&self, v: &CacheVertex) -> CacheQuery {
        let (lo, extent) = self.frame_of;
        CacheQuery {
            position: ((v.p - lo) / extent * 2.0 - 1.0).to_array(),
            dir: v.wo,
            normal: v.normal,
            roughness: v.roughness,
            kd: v.kd,
            ks: v.ks,
        }
    }

    /// One frame through `camera` under `env` (as placed in the world): its radiance per
    /// pixel, read from the cache as it stands; then the cache trains on the frame's training
    /// paths.
    pub fn frame(
        &mut self,
        ts: &TraceScene,
        camera: &Camera,
        env: &EnvMap,
        s: &PathSettings,
    ) -> Vec<Vec3> {
        let (w, h) = (camera.width as usize, camera.height as usize);
        let seed = self.seed ^ self.frames.wrapping_mul(0x9e37_79b9);
        self.frames += 1;
        let o = self.settings;
        // Per pixel: its rendering paths, and maybe one training path.
        let paths: Vec<(Vec<CachedPath>, Option<CachedPath>)> = (0..w * h)
            .into_par_iter()
            .map(|i| {
                let mut rng = pixel_rng(seed, i as u64);
                let ray = CameraRay::centre(ts, camera, i % w, i / w);
                let render = CachePath {
                    read: o.read,
                    train: false,
                    unbiased: false,
                };
                let rendered = (0..o.spp)
                    .map(|_| trace_cached(ts, env, &ray, s, render, &mut rng))
                    .collect();
                let training = (rng.random::<f32>() < o.train_share).then(|| {
                    let how = CachePath {
                        train: true,
                        unbiased: rng.random::<f32>() < o.unbiased_share,
                        ..render
                    };
                    trace_cached(ts, env, &ray, s, how, &mut rng)
                });
                (rendered, training)
            })
            .collect();
        // Every read of the frame, rendering and training, in one pass over the cache.
        let reads: Vec<CacheQuery> = paths
            .iter()
            .flat_map(|(r, t)| r.iter().chain(t))
            .filter_map(|p| p.read.map(|(v, _)| self.query(&v)))
            .collect();
        let mut cached = self.trainer.read(&reads).into_iter();
        let mut value = |p: &CachedPath| match p.read {
            Some(_) => cached.next().expect("a value per read"),
            None => Vec3::ZERO,
        };
        let mut frame = Vec::with_capacity(w * h);
        let (mut queries, mut targets) = (Vec::new(), Vec::new());
        for (rendered, training) in &paths {
            let sum: Vec3 = rendered
                .iter()
                .map(|p| p.radiance + p.read.map_or(Vec3::ZERO, |(_, beta)| beta * value(p)))
                .sum();
            frame.push(sum / o.spp as f32);
            if let Some(t) = training {
                for (v, target) in t.targets(value(t)) {
                    if target.is_finite() {
                        queries.push(self.query(&v));
                        targets.push(target);
                    }
                }
            }
        }
        // Batches of pairs from all over the frame, not from neighbouring pixels.
        let mut order: Vec<usize> = (0..queries.len()).collect();
        order.shuffle(&mut pixel_rng(seed, u64::MAX));
        let queries: Vec<CacheQuery> = order.iter().map(|&k| queries[k]).collect();
        let targets: Vec<Vec3> = order.iter().map(|&k| targets[k]).collect();
        self.trainer.train(&queries, &targets, o.steps, o.batch);
        frame
    }
}

#[cfg(test)]
mod tests {
    use super::steps_within;

    #[test]
    fn training_fills_what_rendering_leaves_of_the_budget() {
        // 20 ms a frame, 8 of them rendering, 2.5 a step: four steps fit, five do not.
        assert_eq!(steps_within(20.0, 8.0, 2.5), 4);
        // Over budget already: it still trains, once.
        assert_eq!(steps_within(5.0, 8.0, 2.5), 1);
        assert_eq!(steps_within(1e6, 1.0, 1.0), 16);
    }
}
