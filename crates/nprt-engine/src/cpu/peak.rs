//! The machine's f32 peak, to put the engine's achieved GFLOP/s in proportion.

use std::time::Instant;

use rayon::prelude::*;

/// The measured f32 peak of a number of threads.
#[derive(Clone, Copy, Debug)]
pub struct Peak {
    pub gflops: f64,
    pub threads: usize,
    /// f32 lanes of the widest FMA units found (16: AVX-512, 8: AVX2, 1: none).
    pub lanes: usize,
}

/// Independent FMA chains, each one vector register wide: enough to cover the FMA latency on
/// two units, few enough to stay in registers.
const CHAINS: usize = 12;

/// `rounds` rounds of CHAINS independent vector multiply-adds kept in registers; returns a lane
/// of their sum so that nothing is optimised away. Written with intrinsics because a plain loop
/// was measured to lose its vectorisation between builds (the "peak" fell from 222 to 9 GFLOP/s).
macro_rules! fma_chains {
    ($name:ident, $feature:literal, $vec:ty, $set1:ident, $fmadd:ident, $add:ident, $cvt:ident) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feature)]
        fn $name(rounds: usize, seed: f32) -> f32 {
            use std::arch::x86_64::*;
            let (a, b) = ($set1(0.999_999_9), $set1(1e-7));
            let mut acc: [$vec; CHAINS] = [$set1(seed); CHAINS];
            for _ in 0..rounds {
                for x in acc.iter_mut() {
                    *x = $fmadd(*x, a, b);
                }
            }
            $cvt(acc.iter().fold($set1(0.0), |s, &x| $add(s, x)))
        }
    };
}

fma_chains!(
    fma_rounds_16,
    "avx512f",
    __m512,
    _mm512_set1_ps,
    _mm512_fmadd_ps,
    _mm512_add_ps,
    _mm512_cvtss_f32
);
fma_chains!(
    fma_rounds_8,
    "avx2,fma",
    __m256,
    _mm256_set1_ps,
    _mm256_fmadd_ps,
    _mm256_add_ps,
    _mm256_cvtss_f32
);

/// Scalar chains where no vector FMA is found.
fn fma_rounds_1(rounds: usize, seed: f32) -> f32 {
    let mut acc = [seed; CHAINS];
    for _ in 0..rounds {
        for x in acc.iter_mut() {
            *x = x.mul_add(0.999_999_9, 1e-7);
        }
    }
    acc.iter().sum()
}

/// f32 peak of `threads` threads, measured: each runs register-resident FMA chains for about
/// 0.2 s (best of three), compiled for the widest FMA units the CPU has (turbo clocks included, which a
/// clock × width estimate would miss).
pub fn measured_peak(threads: usize) -> Peak {
    let lanes = lanes();
    let run = |rounds, seed| match lanes {
        // SAFETY: `lanes` found the CPU features each function is compiled for.
        #[cfg(target_arch = "x86_64")]
        16 => unsafe { fma_rounds_16(rounds, seed) },
        #[cfg(target_arch = "x86_64")]
        8 => unsafe { fma_rounds_8(rounds, seed) },
        _ => fma_rounds_1(rounds, seed),
    };
    // About 0.2 s at 3 GHz on two 256-bit FMA units.
    let rounds = 2_000_000_000 / (CHAINS * lanes.max(8));
    let flops_per_call = (rounds * CHAINS * lanes * 2) as f64;
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
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            return 8;
        }
    }
    1
}
