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

/// [`block_rms`] over the blocks bar the 2% that differ most: two frames of a few hundred
/// paths a pixel under a sun differ most where either drew one of its rare bright paths, and
/// those few blocks make the plain rms a fragile figure; a bias over a region still shows, in
/// many blocks.
pub fn trimmed_block_rms(a: &[glam::Vec3], b: &[glam::Vec3], width: usize) -> f64 {
    let (a, b) = (blocks(a, width), blocks(b, width));
    let mean = a.iter().sum::<f64>() / a.len() as f64;
    let mut sq: Vec<f64> = a.iter().zip(&b).map(|(x, y)| (x - y).powi(2)).collect();
    sq.sort_by(f64::total_cmp);
    let kept = &sq[..sq.len() - sq.len() / 50];
    (kept.iter().sum::<f64>() / kept.len() as f64).sqrt() / mean
}
