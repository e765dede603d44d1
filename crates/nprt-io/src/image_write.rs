//! The one image writer for linear RGB, the reader's counterpart: by the file's extension
//! OpenEXR (f32 R, G, B, exact), Radiance HDR (linear) or PNG (8-bit sRGB, scaled by
//! 2^exposure), written atomically and never holding NaN or infinity.

use std::path::Path;

use anyhow::{bail, Result};
use glam::Vec3;

use crate::atomic::write_atomically;

/// Writes `rgb` (`width × height`, row-major, top row first) to `path` in the format its
/// extension names (.exr, .hdr, .png); `exposure` scales a PNG's radiance by 2^exposure
/// before its sRGB curve (the float formats keep radiance as it is).
pub fn write_linear_rgb(
    path: &Path,
    rgb: &[Vec3],
    width: usize,
    height: usize,
    exposure: f32,
) -> Result<()> {
    if rgb.len() != width * height {
        bail!("{} pixels for a {width}×{height} image", rgb.len());
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "png" => crate::write_png(rgb, width, height, exposure, path),
        "exr" => {
            let channel = |k: usize| rgb.iter().map(|c| c[k]).collect::<Vec<f32>>();
            let channels = ["R", "G", "B"].map(String::from);
            let channels: Vec<_> = (0..3).map(|k| (channels[k].clone(), channel(k))).collect();
            crate::exr::write_channels(path, width, height, &channels)
        }
        "hdr" => {
            let ok = |v: Vec3| v.is_finite() && v.min_element() >= 0.0;
            let want = "finite and non-negative, as Radiance HDR holds";
            crate::png::check_pixels(path, rgb, width, ok, want)?;
            let flat: Vec<f32> = rgb.iter().flat_map(|c| c.to_array()).collect();
            let Some(img) = image::Rgb32FImage::from_raw(width as u32, height as u32, flat) else {
                bail!("a {width}×{height} image is too large for Radiance HDR");
            };
            write_atomically(path, |tmp| {
                Ok(image::DynamicImage::ImageRgb32F(img)
                    .save_with_format(tmp, image::ImageFormat::Hdr)?)
            })
        }
        _ => bail!(
            "'{}': write .exr, .hdr or .png (the extension picks the format)",
            path.display()
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each format read back by the one reader: EXR exactly, HDR within its 8-bit mantissa,
    /// PNG within its 8-bit sRGB steps.
    #[test]
    fn written_images_read_back() {
        let dir = std::env::temp_dir().join(format!("nprt-image-write-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let rgb: Vec<Vec3> = (0..12)
            .map(|i| Vec3::new(i as f32 / 12.0, 0.5, 1.0 - i as f32 / 24.0))
            .collect();
        for (name, tol) in [("a.exr", 0.0), ("a.hdr", 0.01), ("a.png", 0.01)] {
            let path = dir.join(name);
            write_linear_rgb(&path, &rgb, 4, 3, 0.0).unwrap();
            let back = crate::read_linear_rgb(&path, false).unwrap();
            assert_eq!((back.width, back.height), (4, 3), "{name}");
            for (a, b) in back.texels.iter().zip(&rgb) {
                assert!((*a - *b).abs().max_element() <= tol, "{name}: {a} vs {b}");
            }
        }
        let err = write_linear_rgb(&dir.join("a.tiff"), &rgb, 4, 3, 0.0).unwrap_err();
        assert!(err.to_string().contains(".exr, .hdr or .png"), "{err}");
        let mut bad = rgb.clone();
        bad[5] = Vec3::splat(f32::NAN);
        for name in ["b.exr", "b.hdr", "b.png"] {
            assert!(
                write_linear_rgb(&dir.join(name), &bad, 4, 3, 0.0).is_err(),
                "{name}"
            );
            assert!(!dir.join(name).exists(), "{name}");
        }
        std::fs::remove_dir_all(dir).ok();
    }
}
