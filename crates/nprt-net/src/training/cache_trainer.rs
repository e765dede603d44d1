//! The radiance cache trained online, on either engine ([`CacheSteps`], made by
//! [`Engine::cache_steps`]): the CPU engine (its loss and gradients, then the host's Adam) or
//! the GPU kernels (`gpu::GpuCache`: weights, gradients and Adam's moments on the device).

use anyhow::Result;
use glam::Vec3;

use crate::engine::Engine;
use crate::network::radiance_cache::{CacheQuery, CacheSteps, RadianceCache};

/// A cache trained online: its weights and Adam's state on an engine.
pub struct CacheTrainer {
    on: Box<dyn CacheSteps>,
    pub learning_rate: f64,
}

impl CacheTrainer {
    /// `cache` to train on `engine` at `learning_rate`.
    pub fn new(cache: RadianceCache, learning_rate: f64, engine: Engine) -> Result<Self> {
        Ok(CacheTrainer {
            on: engine.cache_steps(cache)?,
            learning_rate,
        })
    }

    /// The weights as they stand.
    pub fn cache(&self) -> RadianceCache {
        self.on.cache()
    }

    /// The radiance the cache holds for each query.
    pub fn read(&mut self, queries: &[CacheQuery]) -> Vec<Vec3> {
        self.on.read(queries)
    }

    /// `steps` Adam steps on consecutive batches of `batch` of the pairs (wrapping around);
    /// returns the mean loss over the steps.
    pub fn train(
        &mut self,
        queries: &[CacheQuery],
        targets: &[Vec3],
        steps: usize,
        batch: usize,
    ) -> f64 {
        if queries.is_empty() || steps == 0 {
            return f64::NAN;
        }
        let batch = batch.clamp(1, queries.len());
        let lr = self.learning_rate;
        let mut total = 0.0;
        for s in 0..steps {
            let from = (s * batch) % queries.len();
            let to = (from + batch).min(queries.len());
            let (q, t) = (&queries[from..to], &targets[from..to]);
            total += self.on.step(q, t, lr);
        }
        total / steps as f64
    }
}
