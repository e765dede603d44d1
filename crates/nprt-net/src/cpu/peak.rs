//! The machine's f32 peak, to put the engine's achieved GFLOP/s in proportion.

use std::time::Instant;

use multiversion::multiversion;
use rayon::prelude::*;

/// The measured f32 peak of a number of threads.
#[derive(Clone, Copy, Debug)]
pub struct Peak {
    pub gflops: f64,
    pub threads: usize,
    /// f32 lanes of the widest FMA units found (16: AVX-512, 8: AVX2 or the portable path).
    pub lanes: usize,
}

/// Independent FMA chains, each one vector register wide: enough to cover the FMA latency on
/// two units, few enough to stay in registers.
const CHAINS: usize = 12;

/// `rounds` rounds of CHAINS × W independent multiply-adds kept in registers; returns their
/// sum so that nothing is optimised away.
#[inline(always)]
fn fma_rounds<const W: usize>(rounds: usize, seed: f32) -> f32 {
    let mut acc = [[seed; W]; CHAINS];
    let (a, b) = (0.999_999_9f32, 1e-7f32);
    for _ in 0..rounds {
        for chain in acc.iter_mut() {
            for x in chain.iter_mut() {
                *x = x.mul_add(a, b);
            }
        }
    }
    acc.iter().flatten().sum()
}

#[multiversion(targets("x86_64+avx512f+avx512vl+fma"))]
fn fma_rounds_16(rounds: usize, seed: f32) -> f32 {
    fma_rounds::<16>(rounds, seed)
}

#[multiversion(targets("x86_64+avx2+fma", "aarch64+neon"))]
fn fma_rounds_8(rounds: usize, seed: f32) -> f32 {
    fma_rounds::<8>(rounds, seed)
}

/// f32 peak of `threads` threads, measured: each runs register-resident FMA chains for about
/// 0.2 s (best of three), compiled for the widest FMA units the CPU has (turbo clocks included, which a
/// clock × width estimate would miss).
pub fn measured_peak(threads: usize) -> Peak {
    let lanes = lanes();
    let run = |rounds, seed| match lanes {
        16 => fma_rounds_16(rounds, seed),
        _ => fma_rounds_8(rounds, seed),
    };
    // About 0.2 s at 3 GHz on two 256-bit FMA units.
    let rounds = 2_000_000_000 / (CHAINS * lanes.max(8));
    let flops_per_call = (rounds * CHAINS * lanes.max(8) * 2) as f64;
    run(rounds / 10, 1.0);
    // The best of three: a thread that starts late only makes a run look slower.
    let seconds = (0..3)
        .map(|_| {
            let start = Instant::now();
            let sum: f32 = (0..threads)
                .into_par_iter()
                .map(|t| run(rounds, t as f32))
                .sum();
            assert!(sum.is_finite());
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min);
    Peak {
        gflops: flops_per_call * threads as f64 / seconds / 1e9,
        threads,
        lanes,
    }
}

fn lanes() -> usize {
    #[cfg(target_arch = "x86_64")]
    {
        if is_x86_feature_detected!("avx512f") {
            return 16;
        }
    }
    8
}
