//! The report's pictures: exposed frames, heat maps of the relative error and magnified crops
//! around the largest error, saved as PNG beside report.md.

use std::path::Path;

use anyhow::Result;
use glam::Vec3;
use nprt_io::{srgb_to_linear, to_image, write_atomically};
use nprt_scene::luminance;

use crate::metrics::RELATIVE_EPS;
use crate::shown_view::ShownView;

/// Relative error at which the heat map saturates.
pub(super) const HEAT_MAX: f32 = 0.5;
/// Magnification of crops.
pub(super) const ZOOM: usize = 3;

/// Exposure (stops) putting the 90th percentile of the foreground's luminance in `reference`
/// at 0.7.
pub fn auto_exposure(reference: &[Vec3], mask: &[f32]) -> f32 {
    let mut l: Vec<f32> = (0..mask.len())
        .filter(|&i| mask[i] > 0.5)
        .map(|i| luminance(reference[i]))
        .collect();
    if l.is_empty() {
        return 0.0;
    }
    l.sort_by(f32::total_cmp);
    (0.7 / l[l.len() * 9 / 10].max(1e-6)).log2()
}

/// Black → purple → orange → pale yellow.
pub(super) fn heat(t: f32) -> Vec3 {
    const STOPS: [Vec3; 4] = [
        Vec3::new(0.0, 0.0, 0.02),
        Vec3::new(0.45, 0.07, 0.5),
        Vec3::new(0.95, 0.45, 0.1),
        Vec3::new(1.0, 1.0, 0.75),
    ];
    let x = t.clamp(0.0, 1.0) * 3.0;
    let i = (x as usize).min(2);
    STOPS[i].lerp(STOPS[i + 1], x - i as f32)
}

/// Per-pixel relative L1 error as colours (linear values that encode to the colour map).
pub(super) fn heat_map(pred: &[Vec3], v: &ShownView) -> Vec<Vec3> {
    (0..v.mask.len())
        .map(|i| {
            if v.mask[i] <= 0.5 {
                return Vec3::splat(0.5);
            }
            let r = v.reference[i];
            let e = (pred[i] - r).abs().element_sum() / (r.element_sum() + 3.0 * RELATIVE_EPS);
            // The PNG writer sRGB-encodes; decode so the colour map is what shows.
            heat(e / HEAT_MAX).map(srgb_to_linear)
        })
        .collect()
}

/// `rgb` on its foreground, the reference's pixels elsewhere: the networks leave the background
/// black (the renderer draws the map there), which no metric scores, so pictures show the
/// methods' differences where they are measured.
pub(super) fn with_background(rgb: &[Vec3], v: &ShownView) -> Vec<Vec3> {
    rgb.iter()
        .zip(&v.reference)
        .zip(&v.mask)
        .map(|((&p, &r), &m)| if m > 0.5 { p } else { r })
        .collect()
}

/// The square window (x0, y0, side) around the largest error of `pred`, smoothed over the
/// window.
pub(super) fn crop_window(pred: &[Vec3], v: &ShownView) -> (usize, usize, usize) {
    let side = (v.width.min(v.height) / 3)
        .max(8)
        .min(v.width.min(v.height));
    let err: Vec<f32> = (0..v.mask.len())
        .map(|i| {
            if v.mask[i] > 0.5 {
                (pred[i] - v.reference[i]).abs().element_sum()
            } else {
                0.0
            }
        })
        .collect();
    let mut best = (0.0, 0, 0);
    let step = (side / 4).max(1);
    for y0 in (0..=v.height - side).step_by(step) {
        for x0 in (0..=v.width - side).step_by(step) {
            let s: f32 = (y0..y0 + side)
                .flat_map(|y| (x0..x0 + side).map(move |x| (x, y)))
                .map(|(x, y)| err[y * v.width + x])
                .sum();
            if s > best.0 {
                best = (s, x0, y0);
            }
        }
    }
    (best.1, best.2, side)
}

pub(super) fn crop(img: &[Vec3], width: usize, (x0, y0, side): (usize, usize, usize)) -> Vec<Vec3> {
    let n = side * ZOOM;
    (0..n * n)
        .map(|i| img[(y0 + (i / n) / ZOOM) * width + x0 + (i % n) / ZOOM])
        .collect()
}

pub(super) fn save(
    dir: &Path,
    name: &str,
    rgb: &[Vec3],
    w: usize,
    h: usize,
    exposure: f32,
) -> Result<String> {
    let file = format!("images/{name}.png");
    let img = to_image(rgb, w, h, exposure);
    let path = dir.join(&file);
    write_atomically(&path, |tmp| {
        Ok(img.save_with_format(tmp, image::ImageFormat::Png)?)
    })?;
    Ok(file)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pictures_take_the_references_background_and_keep_the_foreground() {
        let v = ShownView {
            index: 0,
            width: 2,
            height: 1,
            mask: vec![1.0, 0.0],
            reference: vec![Vec3::splat(0.5), Vec3::splat(3.0)],
            methods: vec![],
        };
        let network = [Vec3::splat(0.4), Vec3::ZERO];
        assert_eq!(
            with_background(&network, &v),
            [Vec3::splat(0.4), Vec3::splat(3.0)]
        );
    }
}
