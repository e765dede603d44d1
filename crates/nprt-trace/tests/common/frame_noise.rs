//! Frames that agree within noise, compared over blocks of pixels.

/// Pixels per side of [`block_rms`]'s blocks.
const BLOCK: usize = 4;

/// Means of `BLOCK`² pixels of a frame `width` wide (its channels summed), for comparing
/// frames that agree within noise: blocks average the noise down, and many of them show where
/// one frame is biased.
fn blocks(frame: &[glam::Vec3], width: usize) -> Vec<f64> {
    let (bw, bh) = (width / BLOCK, frame.len() / width / BLOCK);
    let mut out = vec![0.0; bw * bh];
    for y in 0..bh * BLOCK {
        for x in 0..bw * BLOCK {
            let c = frame[y * width + x];
            out[(y / BLOCK) * bw + x / BLOCK] += (c.x + c.y + c.z) as f64;
        }
    }
    out
}

/// The root mean square difference of two frames' blocks, relative to the first's mean block.
pub fn block_rms(a: &[glam::Vec3], b: &[glam::Vec3], width: usize) -> f64 {
    let (a, b) = (blocks(a, width), blocks(b, width));
    let mean = a.iter().sum::<f64>() / a.len() as f64;
    let ms = a.iter().zip(&b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64;
    ms.sqrt() / mean
}
