//! Seeded parameter initialisation.

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Seeded source of initial parameters: one seed gives one model, drawn in construction order.
pub struct Init {
    rng: Pcg64Mcg,
}

impl Init {
    pub fn new(seed: u64) -> Self {
        Init {
            rng: Pcg64Mcg::seed_from_u64(seed ^ 0x6e70_7274_5f69_6e69),
        }
    }

    /// `n` values drawn uniformly from [−bound, bound].
    pub fn uniform(&mut self, n: usize, bound: f32) -> Vec<f32> {
        (0..n)
            .map(|_| (self.rng.random::<f32>() * 2.0 - 1.0) * bound)
            .collect()
    }
}
