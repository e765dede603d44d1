//! The 19 per-pixel network inputs: their layout and how they are made from a surface point or
//! a G-buffer pixel (for training, the renderer and Deep Shading alike).

use glam::Vec3;
use nprt_trace::{GBuffer, GSample};

/// Floats per pixel: x (3, normalised), ωo (3), ωr (3), n (3), kd (3), ks (3), α (1).
pub const FEATURES: usize = 19;
/// Offsets of each input in the feature vector.
pub mod feature {
    use std::ops::Range;
    pub const POSITION: Range<usize> = 0..3;
    pub const VIEW: Range<usize> = 3..6;
    pub const MIRROR: Range<usize> = 6..9;
    pub const NORMAL: Range<usize> = 9..12;
    pub const KD: Range<usize> = 12..15;
    pub const KS: Range<usize> = 15..18;
    pub const ALPHA: Range<usize> = 18..19;
}

/// How a position is normalised within `bounds`: x ↦ (x − lo) / extent · 2 − 1, with `lo` their
/// minimum and `extent` their size, at least 1e-6 a side (a flat scene). The GPU kernels take
/// the same two vectors.
pub fn position_frame(bounds: &[[f32; 3]; 2]) -> (Vec3, Vec3) {
    let (lo, hi) = (Vec3::from(bounds[0]), Vec3::from(bounds[1]));
    (lo, (hi - lo).max(Vec3::splat(1e-6)))
}

/// The 19 network inputs of one surface point, in the order of [`feature`].
/// `bounds` normalises the position to [−1, 1]; ωr is ωo mirrored about n.
pub fn pixel_features(
    bounds: &[[f32; 3]; 2],
    position: Vec3,
    normal: Vec3,
    view: Vec3,
    kd: Vec3,
    ks: Vec3,
    alpha: f32,
) -> [f32; FEATURES] {
    let (lo, extent) = position_frame(bounds);
    let x = (position - lo) / extent * 2.0 - 1.0;
    let mirror = 2.0 * normal.dot(view) * normal - view;
    let mut f = [0.0; FEATURES];
    for (i, v) in [x, view, mirror, normal, kd, ks].iter().enumerate() {
        f[3 * i..3 * i + 3].copy_from_slice(&v.to_array());
    }
    f[18] = alpha;
    f
}

/// The 19 inputs of pixel `i` of a G-buffer.
pub fn gbuffer_features(bounds: &[[f32; 3]; 2], g: &GBuffer, i: usize) -> [f32; FEATURES] {
    sample_features(bounds, &g.sample(i))
}

/// The 19 inputs of a G-buffer sample.
pub fn sample_features(bounds: &[[f32; 3]; 2], s: &GSample) -> [f32; FEATURES] {
    pixel_features(bounds, s.position, s.normal, s.view, s.kd, s.ks, s.alpha)
}
