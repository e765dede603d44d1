//! The radiance cache on the CPU engine: its queries encoded, read in parallel blocks of rows,
//! and the relative L2 loss of its radiance against path-traced targets with every weight's
//! gradient (the hash grid's through the encoding's adjoint).

use glam::Vec3;
use rayon::prelude::*;

use super::dense::{Pass, Tape};
use super::matmul::MatRef;
use crate::encoding::hash_grid::{self, Corners};
use crate::encoding::spherical_harmonics::basis;
use crate::loss::Loss;
use crate::network::radiance_cache::CacheSteps;
use crate::network::radiance_cache::{CacheQuery, RadianceCache, INPUTS, SH_BANDS};
use crate::optimiser::Adam;
use crate::parameters::Parameters;

/// Rows a task reads or trains on at once.
const BLOCK: usize = 1024;

/// The queries' input rows but for the grid's columns (the first [`hash_grid::OUTPUTS`] of
/// each, left as they are): the SH encodings of direction and normal, 1 − e^−α, kd and ks.
/// The GPU kernels take these too, and fill in the grid themselves.
pub(crate) fn encode_rest(queries: &[CacheQuery], x: &mut [f32]) {
    let sh = SH_BANDS * SH_BANDS;
    for (q, row) in queries.iter().zip(x.chunks_exact_mut(INPUTS)) {
        let rest = &mut row[hash_grid::OUTPUTS..];
        let (dir, rest) = rest.split_at_mut(sh);
        basis(SH_BANDS, q.dir, dir);
        let (normal, rest) = rest.split_at_mut(sh);
        basis(SH_BANDS, q.normal, normal);
        rest[0] = 1.0 - (-q.roughness).exp();
        rest[1..4].copy_from_slice(&q.kd.to_array());
        rest[4..7].copy_from_slice(&q.ks.to_array());
    }
}

/// `queries` as the MLP's input rows, and where each reads the grid.
fn encode(cache: &RadianceCache, queries: &[CacheQuery]) -> (Vec<f32>, Vec<Corners>) {
    let mut x = vec![0.0; queries.len() * INPUTS];
    encode_rest(queries, &mut x);
    let corners = (queries.iter().zip(x.chunks_exact_mut(INPUTS)))
        .map(|(q, row)| {
            let c = hash_grid::corners(q.position);
            hash_grid::encode(&cache.grid.table, &c, &mut row[..hash_grid::OUTPUTS]);
            c
        })
        .collect();
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

/// The cache on the CPU engine: its weights and the host's Adam.
pub struct HostCacheSteps {
    pub cache: RadianceCache,
    pub adam: Adam,
}

impl CacheSteps for HostCacheSteps {
    fn cache(&self) -> RadianceCache {
        self.cache.clone()
    }

    fn read(&mut self, queries: &[CacheQuery]) -> Vec<Vec3> {
        self.cache.read(queries)
    }

    fn step(&mut self, queries: &[CacheQuery], targets: &[Vec3], lr: f64) -> f64 {
        let (loss, grads) = self.cache.loss_and_gradients(queries, targets);
        self.adam.step(&mut self.cache, &grads, lr);
        loss
    }
}
