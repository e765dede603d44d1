//! Where a path's random numbers come from. The integrators draw their uniform numbers through
//! [`Sampler`], one dimension after another: a plain random stream (every path tracer's, as
//! Mitsuba 3's `independent` sampler) or [`StratifiedSampler`], which spreads a pixel's samples
//! over each of a path's first dimensions (Latin hypercube sampling, McKay et al. 1979): the
//! traced direct light of a relit frame, a few samples a pixel, is the less noisy for it at the
//! same cost.

use rand::RngExt;
use rand_pcg::Pcg64Mcg;

/// A source of uniform numbers in [0, 1), drawn in the order a path uses them.
pub trait Sampler {
    fn next_f32(&mut self) -> f32;
}

impl Sampler for Pcg64Mcg {
    fn next_f32(&mut self) -> f32 {
        self.random()
    }
}

/// Dimensions of a sample that are stratified: a direct-light path's first vertex draws six
/// (a light sample, three; a BSDF sample, three); later draws are plain random numbers.
/// path_trace.wgsl's `STRATIFIED_DIMENSIONS` is the same.
pub const STRATIFIED_DIMENSIONS: u32 = 6;

/// One pixel's `n` samples, each of its first [`STRATIFIED_DIMENSIONS`] dimensions Latin
/// hypercube sampled: over the pixel's samples, dimension d takes exactly one value in each of
/// the n strata [k/n, (k+1)/n), jittered, the strata assigned to samples by a random
/// permutation of each dimension's own ([`permute`], keyed by the pixel). Each value is uniform
/// on [0, 1) and the dimensions of one sample are independent, so every sample's estimate is
/// unbiased, as with independent numbers; across the pixel's samples they cover each dimension
/// evenly. The GPU's traced direct light (path_trace.wgsl) stratifies the same way.
pub struct StratifiedSampler {
    rng: Pcg64Mcg,
    /// The pixel's key: each dimension's permutation is keyed by it.
    key: u32,
    n: u32,
    /// The sample under way and the dimension it draws next.
    sample: u32,
    dimension: u32,
}

impl StratifiedSampler {
    /// `n` samples drawn from `rng`'s stream.
    pub fn new(mut rng: Pcg64Mcg, n: u32) -> Self {
        StratifiedSampler {
            key: rng.random(),
            rng,
            n: n.max(1),
            sample: 0,
            dimension: 0,
        }
    }

    /// Begins sample `s` (0 ≤ s < n): its draws start again at the first dimension.
    pub fn start(&mut self, s: u32) {
        self.sample = s % self.n;
        self.dimension = 0;
    }
}

impl Sampler for StratifiedSampler {
    fn next_f32(&mut self) -> f32 {
        let d = self.dimension;
        self.dimension += 1;
        let jitter: f32 = self.rng.random();
        if d >= STRATIFIED_DIMENSIONS {
            return jitter;
        }
        stratum_value(self.sample, self.n, dimension_key(self.key, d), jitter)
    }
}

/// Dimension `d`'s permutation key for the pixel keyed `key` (PCG's output hash, as
/// path_trace.wgsl's `pcg_hash`).
pub fn dimension_key(key: u32, d: u32) -> u32 {
    let s = (key ^ d.wrapping_mul(0x9e37_79b9))
        .wrapping_mul(747_796_405)
        .wrapping_add(2_891_336_453);
    let w = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277_803_737);
    (w >> 22) ^ w
}

/// Sample `s` of `n` in the stratum `permute(s, n, key)`, at `jitter` within it; below 1 even
/// where rounding would reach it.
pub fn stratum_value(s: u32, n: u32, key: u32, jitter: f32) -> f32 {
    ((permute(s, n, key) as f32 + jitter) / n as f32).min(1.0 - f32::EPSILON / 2.0)
}

/// A permutation of 0..l chosen by `p`: Kensler's hashed permutation ("Correlated Multi-Jittered
/// Sampling", Pixar 2013), which needs no table, by cycle walking within the next power of two.
/// path_trace.wgsl's `permute` is the same arithmetic.
pub fn permute(mut i: u32, l: u32, p: u32) -> u32 {
    let mut w = l.max(1) - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    loop {
        i ^= p;
        i = i.wrapping_mul(0xe170_893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | p >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < l.max(1) {
            return (i + p % l.max(1)) % l.max(1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pixel_rng::pixel_rng;

    #[test]
    fn each_dimension_takes_one_value_in_each_stratum() {
        let n = 13;
        let mut s = StratifiedSampler::new(pixel_rng(7, 3), n);
        let mut seen = vec![vec![0; n as usize]; STRATIFIED_DIMENSIONS as usize + 1];
        for k in 0..n {
            s.start(k);
            for dims in seen.iter_mut() {
                let u = s.next_f32();
                assert!((0.0..1.0).contains(&u), "{u}");
                dims[(u * n as f32) as usize] += 1;
            }
        }
        for (d, strata) in seen.iter().enumerate().take(STRATIFIED_DIMENSIONS as usize) {
            assert_eq!(*strata, vec![1; n as usize], "dimension {d}");
        }
        // Past the stratified dimensions, plain random numbers: some stratum is missed.
        assert!(seen[STRATIFIED_DIMENSIONS as usize].contains(&0));
    }

    #[test]
    fn permute_is_a_permutation_for_every_length_and_key() {
        for l in [1, 2, 3, 7, 16, 17, 100, 1024] {
            for p in [0, 1, 0xdead_beef, u32::MAX] {
                let mut seen = vec![false; l as usize];
                for i in 0..l {
                    let j = permute(i, l, p) as usize;
                    assert!(!seen[j], "l {l} p {p}: {j} twice");
                    seen[j] = true;
                }
            }
        }
        // Keys give different orders.
        let order = |p| (0..16).map(|i| permute(i, 16, p)).collect::<Vec<_>>();
        assert_ne!(order(1), order(2));
    }

    #[test]
    fn stratified_values_are_uniform_over_many_pixels() {
        // Each draw's mean and second moment, over 4,000 pixels of 4 samples each.
        let (mut sum, mut sq, mut count) = ([0.0f64; 3], [0.0f64; 3], 0.0);
        for p in 0..4000 {
            let mut s = StratifiedSampler::new(pixel_rng(1, p), 4);
            for k in 0..4 {
                s.start(k);
                for d in 0..3 {
                    let u = s.next_f32() as f64;
                    sum[d] += u;
                    sq[d] += u * u;
                }
                count += 1.0;
            }
        }
        for d in 0..3 {
            assert!(
                (sum[d] / count - 0.5).abs() < 0.01,
                "mean {}",
                sum[d] / count
            );
            assert!(
                (sq[d] / count - 1.0 / 3.0).abs() < 0.01,
                "second moment {}",
                sq[d] / count
            );
        }
    }
}
