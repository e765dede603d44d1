//! The radiance cache trained online, on either engine: the CPU engine (its loss and
//! gradients, then the host's Adam) or the GPU kernels (`gpu::GpuCache`: weights, gradients
//! and Adam's moments on the device), read and stepped through one interface.

use anyhow::Result;
use glam::Vec3;

use crate::engine::Engine;
use crate::network::parameters::Parameters;
use crate::network::radiance_cache::{CacheQuery, RadianceCache, ADAM_BETAS};
use crate::optimiser::Adam;

/// Where the cache's weights live and step.
enum CacheOn {
    Cpu {
        cache: RadianceCache,
        adam: Adam,
    },
    #[cfg(feature = "gpu")]
    Gpu(Box<crate::gpu::GpuCache>),
}

/// A cache trained online: its weights and Adam's state on an engine.
pub struct CacheTrainer {
    on: CacheOn,
    pub learning_rate: f64,
}

impl CacheTrainer {
    /// `cache` to train on `engine` at `learning_rate` (the GPU engine in a build with the
    /// kernels; the CPU otherwise).
    pub fn new(cache: RadianceCache, learning_rate: f64, engine: Engine) -> Result<Self> {
        #[cfg(feature = "gpu")]
        if engine.is_gpu() {
            let gpu = crate::gpu::GpuCache::new(&cache, ADAM_BETAS)?;
            return Ok(CacheTrainer {
                on: CacheOn::Gpu(Box::new(gpu)),
                learning_rate,
            });
        }
        #[cfg(not(feature = "gpu"))]
        let _ = engine;
        Ok(CacheTrainer {
            on: CacheOn::Cpu {
                adam: Adam::with_betas(cache.num_params(), ADAM_BETAS),
                cache,
            },
            learning_rate,
        })
    }

    /// The weights as they stand.
    pub fn cache(&self) -> RadianceCache {
        match &self.on {
            CacheOn::Cpu { cache, .. } => cache.clone(),
            #[cfg(feature = "gpu")]
            CacheOn::Gpu(gpu) => gpu.parameters(),
        }
    }

    /// The radiance the cache holds for each query.
    pub fn read(&mut self, queries: &[CacheQuery]) -> Vec<Vec3> {
        match &mut self.on {
            CacheOn::Cpu { cache, .. } => cache.read(queries),
            #[cfg(feature = "gpu")]
            CacheOn::Gpu(gpu) => gpu.read(queries),
        }
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
            total += match &mut self.on {
                CacheOn::Cpu { cache, adam } => {
                    let (loss, grads) = cache.loss_and_gradients(q, t);
                    adam.step(cache, &grads, lr);
                    loss
                }
                #[cfg(feature = "gpu")]
                CacheOn::Gpu(gpu) => gpu.step(q, t, lr),
            };
        }
        total / steps as f64
    }
}
