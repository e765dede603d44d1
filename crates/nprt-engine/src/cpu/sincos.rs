//! sin and cos of a whole slice at once, vectorised: SIREN layers take both (sin forward, its
//! derivative cos backward), and libm's scalar `sinf` per element was a fifth of a SIREN
//! design's training step.
//!
//! Cody–Waite reduction by π/2 in three parts and Cephes' minimax polynomials on [−π/4, π/4],
//! written branch-free so that the compiler vectorises the loop; `multiversion` compiles it for
//! AVX-512, AVX2 + FMA and the portable baseline and picks one at run time. Maximum absolute
//! error against f64 `sin`/`cos` of the same f32 argument: [`MAX_ERROR`] for |x| ≤
//! [`REDUCED_RANGE`] (tested); larger arguments, which a SIREN layer only sees when training has
//! already diverged, fall back to libm so that no input gives a wrong value.

use multiversion::multiversion;

/// Bound on |computed − exact| for |x| ≤ [`REDUCED_RANGE`].
pub const MAX_ERROR: f32 = 4e-7;
/// Arguments up to this size take the vectorised path: the first two parts of π/2 have 8 and 11
/// significant bits, so j·P1 and j·P2 stay exact for the quadrant counts j (< 2^13) it allows.
pub const REDUCED_RANGE: f32 = 8192.0;

const FRAC_2_PI: f32 = std::f32::consts::FRAC_2_PI;
// π/2 = P1 + P2 + P3, P1 and P2 short enough that j·P1 and j·P2 are exact in f32.
const P1: f32 = 1.570_312_5;
const P2: f32 = 4.837_513e-4;
const P3: f32 = 7.549_79e-8;
// Adding and subtracting 1.5·2^23 rounds to the nearest integer without SSE4.1's `roundps`.
const ROUND: f32 = 12_582_912.0;

#[inline(always)]
fn sincos_one(x: f32) -> (f32, f32) {
    let t = x * FRAC_2_PI + ROUND;
    let j = t - ROUND;
    // The quadrant j mod 4 is in t's last mantissa bits (ROUND is a multiple of 4 and |j| is
    // far below 2^22): Rust's saturating `j as i32` would keep the loop scalar.
    let q = t.to_bits();
    let r = ((x - j * P1) - j * P2) - j * P3;
    let z = r * r;
    let s = ((-1.951_529_6e-4 * z + 8.332_161e-3) * z - 1.666_665_5e-1) * z * r + r;
    let c = ((2.443_315_7e-5 * z - 1.388_731_6e-3) * z + 4.166_664_6e-2) * z * z - 0.5 * z + 1.0;
    let swap = q & 1 != 0;
    let (sin, cos) = if swap { (c, s) } else { (s, c) };
    let sin = f32::from_bits(sin.to_bits() ^ ((q & 2) << 30));
    let cos = f32::from_bits(cos.to_bits() ^ ((q.wrapping_add(1) & 2) << 30));
    (sin, cos)
}

/// The vectorised loop of [`sincos_scaled`]. Arguments beyond the reduced range are left in
/// `x`, with NaN in `sin` to mark them; returns whether there were any.
#[multiversion(targets("x86_64+avx512f+avx512vl+fma", "x86_64+avx2+fma", "aarch64+neon"))]
fn sincos_scaled_simd(x: &mut [f32], scale: f32, sin: &mut [f32]) -> bool {
    let mut outside = false;
    for (x, s) in x.iter_mut().zip(sin.iter_mut()) {
        let a = *x * scale;
        let (sa, ca) = sincos_one(a);
        // False for NaN too.
        let inside = a.abs() <= REDUCED_RANGE;
        *s = if inside { sa } else { f32::NAN };
        *x = if inside { scale * ca } else { *x };
        outside |= !inside;
    }
    outside
}

/// For every i: `sin[i] = sin(scale·x[i])` and then `x[i] = scale·cos(scale·x[i])`: the value
/// and the derivative of a SIREN activation, the derivative kept where the argument was.
pub fn sincos_scaled(x: &mut [f32], scale: f32, sin: &mut [f32]) {
    assert_eq!(x.len(), sin.len());
    if sincos_scaled_simd(x, scale, sin) {
        for (x, s) in x.iter_mut().zip(sin.iter_mut()) {
            if s.is_nan() {
                let a = *x * scale;
                *s = a.sin();
                *x = scale * a.cos();
            }
        }
    }
}

/// The vectorised loop of [`sin_scaled`]: arguments beyond the reduced range are left as they
/// are; returns whether there were any.
#[multiversion(targets("x86_64+avx512f+avx512vl+fma", "x86_64+avx2+fma", "aarch64+neon"))]
fn sin_scaled_simd(x: &mut [f32], scale: f32) -> bool {
    let mut outside = false;
    for x in x.iter_mut() {
        let a = *x * scale;
        let inside = a.abs() <= REDUCED_RANGE;
        *x = if inside { sincos_one(a).0 } else { *x };
        outside |= !inside;
    }
    outside
}

/// `x[i] = sin(scale·x[i])` in place: a SIREN activation where its derivative is not needed
/// (inference), without [`sincos_scaled`]'s second buffer and cos.
pub fn sin_scaled(x: &mut [f32], scale: f32) {
    // A value the loop replaced is at most 1 in size, so with |scale| at most half the range
    // only the arguments it left behind still exceed the range when scaled.
    assert!(scale.abs() <= REDUCED_RANGE / 2.0);
    if sin_scaled_simd(x, scale) {
        for x in x.iter_mut() {
            let a = *x * scale;
            if !(a.abs() <= REDUCED_RANGE) {
                *x = a.sin();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn worst_error(xs: &[f32]) -> f64 {
        let mut sin = vec![0.0; xs.len()];
        let mut cos = xs.to_vec();
        sincos_scaled(&mut cos, 1.0, &mut sin);
        xs.iter()
            .zip(sin.iter().zip(&cos))
            .map(|(&x, (&s, &c))| {
                let x = x as f64;
                (s as f64 - x.sin()).abs().max((c as f64 - x.cos()).abs())
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn agrees_with_f64_over_what_siren_layers_see() {
        // ω0 = 30 times pre-activations of a few units: ±300. A fine sweep of [−1, 1] and a
        // dense one of the whole reduced range.
        let fine: Vec<f32> = (0..2_000_001).map(|i| (i as f32 - 1e6) * 1e-6).collect();
        assert!(
            worst_error(&fine) <= MAX_ERROR as f64,
            "{}",
            worst_error(&fine)
        );
        let wide: Vec<f32> = (0..4_000_001)
            .map(|i| (i as f32 - 2e6) / 2e6 * REDUCED_RANGE)
            .collect();
        let e = worst_error(&wide);
        assert!(
            e <= MAX_ERROR as f64,
            "worst error {e} over ±{REDUCED_RANGE}"
        );
    }

    #[test]
    fn sin_alone_equals_the_pair_s_sin_bit_for_bit() {
        let xs: Vec<f32> = (0..100_001)
            .map(|i| (i as f32 - 5e4) * 3e-4)
            .chain([-1e6, 3e7, f32::NAN, 0.0, 300.0, -273.1])
            .collect();
        let (mut sin, mut cos) = (vec![0.0; xs.len()], xs.clone());
        sincos_scaled(&mut cos, 30.0, &mut sin);
        let mut alone = xs.clone();
        sin_scaled(&mut alone, 30.0);
        for ((a, s), x) in alone.iter().zip(&sin).zip(&xs) {
            assert!(a.to_bits() == s.to_bits(), "sin(30·{x}): {a} against {s}");
        }
    }

    #[test]
    fn scales_and_falls_back_beyond_the_range() {
        let xs = [0.5f32, -1e6, 3e7, f32::NAN, 0.0];
        let (mut s, mut c) = ([0.0; 5], xs);
        sincos_scaled(&mut c, 30.0, &mut s);
        for i in [0, 1, 2, 4] {
            let a = (xs[i] * 30.0) as f64;
            assert!((s[i] as f64 - a.sin()).abs() < 1e-6, "sin {a}");
            assert!((c[i] as f64 - 30.0 * a.cos()).abs() < 3e-5, "cos {a}");
        }
        assert!(s[3].is_nan() && c[3].is_nan());
    }
}
