//! The 2×2 max-pool with stride 2 on the CPU engine, and its adjoint.

/// Pools `channels` planes of h × w values, `value(c · h · w + p)` each: returns the pooled
/// channels × h/2 × w/2 values and, for each, the index in h × w it came from (the first of
/// its window's maxima, in row order).
pub fn max_pool(
    channels: usize,
    (h, w): (usize, usize),
    value: impl Fn(usize) -> f32,
) -> (Vec<f32>, Vec<u32>) {
    let (ph, pw) = (h / 2, w / 2);
    let mut pooled = vec![0.0; channels * ph * pw];
    let mut argmax = vec![0u32; channels * ph * pw];
    for c in 0..channels {
        for y in 0..ph {
            for xo in 0..pw {
                let at = (c * ph + y) * pw + xo;
                let window = [0, 1, w, w + 1].map(|d| 2 * y * w + 2 * xo + d);
                let (best, max) = window
                    .map(|p| (p, value(c * h * w + p)))
                    .into_iter()
                    .reduce(|a, b| if b.1 > a.1 { b } else { a })
                    .expect("a 2×2 window");
                pooled[at] = max;
                argmax[at] = best as u32;
            }
        }
    }
    (pooled, argmax)
}

/// The adjoint of [`max_pool`]: each pooled value's gradient `d_pooled` to the value it took,
/// in channels × `hw` planes.
pub fn unpool(d_pooled: &[f32], argmax: &[u32], hw: usize) -> Vec<f32> {
    let per_channel = hw / 4;
    let mut d = vec![0.0; d_pooled.len() * 4];
    for (i, (&g, &src)) in d_pooled.iter().zip(argmax).enumerate() {
        d[(i / per_channel) * hw + src as usize] = g;
    }
    d
}
