//! Tone-mapped 8-bit PNG images of linear radiance, written atomically.

use std::path::Path;

use anyhow::{bail, Result};
use glam::Vec3;
use image::RgbImage;

use crate::atomic::write_atomically;
use crate::srgb::linear_to_srgb;

/// Linear radiance scaled by 2^exposure, clamped, sRGB-encoded.
pub fn srgb8(c: Vec3, exposure: f32) -> [u8; 3] {
    let scale = exposure.exp2();
    let encode = |c: f32| (linear_to_srgb(c * scale) * 255.0 + 0.5) as u8;
    [encode(c.x), encode(c.y), encode(c.z)]
}

pub fn to_image(rgb: &[Vec3], width: usize, height: usize, exposure: f32) -> RgbImage {
    RgbImage::from_fn(width as u32, height as u32, |x, y| {
        image::Rgb(srgb8(rgb[y as usize * width + x as usize], exposure))
    })
}

/// Refuses to write `rgb` (rows of `width`) to `path` where a pixel is not `ok`, naming the
/// first such pixel and what a pixel must be (`want`).
pub(crate) fn check_pixels(
    path: &Path,
    rgb: &[Vec3],
    width: usize,
    ok: impl Fn(Vec3) -> bool,
    want: &str,
) -> Result<()> {
    if let Some(i) = rgb.iter().position(|&v| !ok(v)) {
        bail!(
            "refusing to write '{}': the radiance at pixel ({}, {}) is {}, not {want}",
            path.display(),
            i % width.max(1),
            i / width.max(1),
            rgb[i]
        );
    }
    Ok(())
}

/// Writes a tone-mapped PNG atomically; refuses non-finite radiance (which tone-maps to a
/// plausible-looking black or white), naming the pixel.
pub fn write_png(
    rgb: &[Vec3],
    width: usize,
    height: usize,
    exposure: f32,
    path: &Path,
) -> Result<()> {
    check_pixels(path, rgb, width, |v| v.is_finite(), "a finite radiance")?;
    let img = to_image(rgb, width, height, exposure);
    write_atomically(path, |tmp| {
        Ok(img.save_with_format(tmp, image::ImageFormat::Png)?)
    })
}
