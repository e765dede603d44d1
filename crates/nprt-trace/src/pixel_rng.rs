//! Per-pixel random streams: independent of thread count and order, so the same seed gives
//! the same image.

use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

/// SplitMix64 finaliser: decorrelates per-pixel seeds.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The random stream of pixel `index` under `seed`: independent of thread count and order, so
/// the same seed gives the same image.
pub fn pixel_rng(seed: u64, index: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(mix(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ mix(index)))
}
