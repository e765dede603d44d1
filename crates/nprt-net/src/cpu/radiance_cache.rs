//! The radiance cache on the CPU engine: its queries encoded, read in parallel blocks of rows,
//! and trained online: the relative L2 loss of its radiance against path-traced targets and
//! every weight's gradient (the hash grid's through the encoding's adjoint), then Adam.

use glam::Vec3;
use rayon::prelude::*;

use super::dense::{Pass, Tape};
use super::matmul::MatRef;
use crate::encoding::hash_grid::{self, Corners};
use crate::encoding::spherical_harmonics::basis;
use crate::loss::Loss;
use crate::network::parameters::Parameters;
use crate::network::radiance_cache::{CacheQuery, RadianceCache, INPUTS, SH_BANDS};
use crate::optimiser::Adam;

/// Adam's β1 and β2 for the cache. β2 is Müller et al.'s 0.99 (not the usual 0.999), and β1
/// 0.5 (theirs is 0.9): their targets move when the light changes, and with β1 0.9 the
/// momentum carried a cache past a tripled sky to twice its value, where relative L2's
/// gradients are weak, and it swung for a dozen frames (tests/nrc.rs in nprt-eval); with 0.5 it
/// settles within two frames.
const BETAS: [f32; 2] = [0.5, 0.99];

/// Rows a task reads or trains on at once.
const BLOCK: usize = 1024;

/// `queries` as the MLP's input rows, and where each reads the grid.
fn encode(cache: &RadianceCache, queries: &[CacheQuery]) -> (Vec<f32>, Vec<Corners>) {
    let mut x = vec![0.0; queries.len() * INPUTS];
    let mut corners = Vec::with_capacity(queries.len());
    let sh = SH_BANDS * SH_BANDS;
    for (q, row) in queries.iter().zip(x.chunks_exact_mut(INPUTS)) {
        let c = hash_grid::corners(q.position);
        let (grid, rest) = row.split_at_mut(hash_grid::OUTPUTS);
        hash_grid::encode(&cache.grid.table, &c, grid);
        let (dir, rest) = rest.split_at_mut(sh);
        basis(SH_BANDS, q.dir, dir);
        let (normal, rest) = rest.split_at_mut(sh);
        basis(SH_BANDS, q.normal, normal);
        rest[0] = 1.0 - (-q.roughness).exp();
        rest[1..4].copy_from_slice(&q.kd.to_array());
        rest[4..7].copy_from_slice(&q.ks.to_array());
        corners.push(c);
    }
    (x, corners)
}

impl RadianceCache {
    /// The radiance the cache holds for each query.
    pub fn read(&self, queries: &[CacheQuery]) -> Vec<Vec3> {
        queries
            .par_chunks(BLOCK)
            .flat_map_iter(|block| {
                let (x, _) = encode(self, block);
                let mut tape = Tape::default();
                let rows = MatRef::new(&x, block.len(), INPUTS);
                self.mlp.forward(rows, None, &mut tape, Pass::Infer);
                let out = tape.output().to_vec();
                (block.iter().zip(out.chunks_exact(3)))
                    .map(|(q, o)| Vec3::from_slice(o) * q.albedo())
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    /// The mean relative L2 loss of the cache's radiance against `targets` over the queries'
    /// channels, and every weight's gradient.
    pub fn loss_and_gradients(
        &self,
        queries: &[CacheQuery],
        targets: &[Vec3],
    ) -> (f64, RadianceCache) {
        let norm = 1.0 / (3 * queries.len()).max(1) as f32;
        let parts: Vec<(f64, RadianceCache)> = (queries.par_chunks(BLOCK))
            .zip(targets.par_chunks(BLOCK))
            .map(|(block, target)| self.block_gradients(block, target, norm))
            .collect();
        let mut grads = self.zeros_like();
        let mut loss = 0.0;
        for (l, g) in &parts {
            loss += l;
            grads.add(g);
        }
        (loss, grads)
    }

    /// One block's share of [`Self::loss_and_gradients`]: its summed loss times `norm`.
    fn block_gradients(
        &self,
        queries: &[CacheQuery],
        targets: &[Vec3],
        norm: f32,
    ) -> (f64, RadianceCache) {
        let (x, corners) = encode(self, queries);
        let rows = MatRef::new(&x, queries.len(), INPUTS);
        let mut tape = Tape::default();
        self.mlp.forward(rows, None, &mut tape, Pass::Train);
        let mut loss = 0.0f64;
        let mut d_out = vec![0.0; queries.len() * 3];
        let out = tape.output();
        for (i, (q, t)) in queries.iter().zip(targets).enumerate() {
            let albedo = q.albedo();
            for c in 0..3 {
                let (value, slope) = Loss::RelL2.element(out[3 * i + c] * albedo[c], t[c]);
                loss += (value * norm) as f64;
                d_out[3 * i + c] = slope * norm * albedo[c];
            }
        }
        let mut grads = self.zeros_like();
        let mut d_x = vec![0.0; x.len()];
        let d_input = Some(d_x.as_mut_slice());
        (self.mlp).backward(
            rows,
            None,
            &mut tape,
            &mut d_out,
            &mut grads.mlp,
            d_input,
            None,
        );
        for (c, d) in corners.iter().zip(d_x.chunks_exact(INPUTS)) {
            hash_grid::scatter(&mut grads.grid.table, c, &d[..hash_grid::OUTPUTS]);
        }
        (loss, grads)
    }
}

/// A cache trained online: its weights and Adam's state.
pub struct CacheTrainer {
    pub cache: RadianceCache,
    adam: Adam,
    pub learning_rate: f64,
}

impl CacheTrainer {
    pub fn new(cache: RadianceCache, learning_rate: f64) -> Self {
        CacheTrainer {
            adam: Adam::with_betas(cache.num_params(), BETAS),
            cache,
            learning_rate,
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
        let mut total = 0.0;
        for s in 0..steps {
            let from = (s * batch) % queries.len();
            let to = (from + batch).min(queries.len());
            let (loss, grads) = self
                .cache
                .loss_and_gradients(&queries[from..to], &targets[from..to]);
            self.adam.step(&mut self.cache, &grads, self.learning_rate);
            total += loss;
        }
        total / steps as f64
    }
}
