//! The one image reader, for textures and environment maps alike: OpenEXR
//! through the exr crate (every compression, first RGB(A) layer), everything else (PNG, JPEG,
//! Radiance HDR) through the image crate. Pixels come back as linear RGB.

use std::path::Path;

use anyhow::{Context, Result};
use glam::Vec3;

use crate::srgb::srgb_to_linear;

/// A decoded image in linear RGB, row-major, top row first.
pub struct LinearImage {
    pub width: usize,
    pub height: usize,
    pub texels: Vec<Vec3>,
}

/// Reads `path` by its content (the extension only picks OpenEXR). Integer formats are
/// sRGB-decoded unless `raw`; floating-point ones are linear already.
pub fn read_linear_rgb(path: &Path, raw: bool) -> Result<LinearImage> {
    crate::check_input(path)?;
    let is_exr = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if is_exr {
        return read_exr(path).with_context(|| format!("cannot read '{}'", path.display()));
    }
    let img = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .with_context(|| format!("cannot open '{}'", path.display()))?
        .decode()
        .with_context(|| format!("cannot decode '{}'", path.display()))?;
    Ok(linear_rgb(img, raw))
}

/// Converts a decoded image, sRGB-decoding integer formats unless `raw`.
pub fn linear_rgb(img: image::DynamicImage, raw: bool) -> LinearImage {
    let float_source = matches!(
        img,
        image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
    );
    let linear = raw || float_source;
    let rgb = img.into_rgb32f();
    let texels = rgb
        .pixels()
        .map(|p| {
            let c = Vec3::new(p[0], p[1], p[2]);
            if linear {
                c
            } else {
                c.map(srgb_to_linear)
            }
        })
        .collect();
    LinearImage {
        width: rgb.width() as usize,
        height: rgb.height() as usize,
        texels,
    }
}

fn read_exr(path: &Path) -> Result<LinearImage> {
    use ::exr::prelude::*;
    crate::exr::checked_size(path)?;
    let image = read_first_rgba_layer_from_file(
        path,
        |res, _| LinearImage {
            width: res.width(),
            height: res.height(),
            texels: vec![Vec3::ZERO; res.width() * res.height()],
        },
        |img, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            img.texels[pos.y() * img.width + pos.x()] = Vec3::new(r, g, b);
        },
    )?;
    Ok(image.layer_data.channel_data.pixels)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same pixels written as 8-bit PNG, Radiance HDR and OpenEXR read back alike: PNG
    /// through the sRGB curve (or raw), the float formats as they are.
    #[test]
    fn png_hdr_and_exr_read_alike() {
        let dir = std::env::temp_dir().join(format!("nprt-image-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let px = |x: u32, y: u32| [x as f32 / 3.0, y as f32 / 2.0, 0.5];
        let png = image::RgbImage::from_fn(4, 3, |x, y| {
            image::Rgb(px(x, y).map(|v| (v * 255.0).round() as u8))
        });
        png.save(dir.join("a.png")).unwrap();
        let float = image::Rgb32FImage::from_fn(4, 3, |x, y| image::Rgb(px(x, y)));
        image::DynamicImage::ImageRgb32F(float.clone())
            .save(dir.join("a.hdr"))
            .unwrap();
        ::exr::prelude::write_rgb_file(dir.join("a.exr"), 4, 3, |x, y| {
            let p = px(x as u32, y as u32);
            (p[0], p[1], p[2])
        })
        .unwrap();
        for (name, raw, tol, curve) in [
            ("a.png", false, 0.01, true),
            ("a.png", true, 0.003, false),
            ("a.hdr", false, 0.01, false),
            ("a.exr", false, 0.0, false),
        ] {
            let img = read_linear_rgb(&dir.join(name), raw).unwrap();
            assert_eq!((img.width, img.height), (4, 3), "{name}");
            for (i, t) in img.texels.iter().enumerate() {
                let want = Vec3::from(px((i % 4) as u32, (i / 4) as u32));
                let want = if curve {
                    want.map(srgb_to_linear)
                } else {
                    want
                };
                assert!(
                    (*t - want).abs().max_element() <= tol,
                    "{name} raw={raw} pixel {i}: {t} vs {want}"
                );
            }
        }
        let err = read_linear_rgb(&dir.join("missing.png"), false)
            .err()
            .unwrap();
        assert!(format!("{err:#}").contains("missing.png"), "{err:#}");
        std::fs::remove_dir_all(dir).ok();
    }

    /// Maps and textures in every compression OpenEXR defines read alike (half floats, the
    /// format B44 needs; the lossy ones within their error).
    #[test]
    fn exr_reads_every_compression() {
        use ::exr::prelude::*;
        let dir = std::env::temp_dir().join(format!("nprt-exr-codecs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (w, h) = (32, 16);
        let px = |x: usize, y: usize| [0.25 + x as f32 / 64.0, 2.0 + y as f32 / 8.0, 0.5];
        for (compression, tol) in [
            (Compression::Uncompressed, 0.0),
            (Compression::RLE, 0.0),
            (Compression::ZIP1, 0.0),
            (Compression::ZIP16, 0.0),
            (Compression::PIZ, 0.0),
            (Compression::PXR24, 0.0),
            (Compression::B44, 0.02),
            (Compression::B44A, 0.02),
            (Compression::DWAA(None), 0.02),
            (Compression::DWAB(None), 0.02),
        ] {
            let layer = Layer::new(
                (w, h),
                LayerAttributes::named("rgb"),
                Encoding {
                    compression,
                    ..Encoding::default()
                },
                SpecificChannels::rgb(|p: Vec2<usize>| {
                    let c = px(p.x(), p.y()).map(f16::from_f32);
                    (c[0], c[1], c[2])
                }),
            );
            let path = dir.join(format!("{compression:?}.exr").replace(['(', ')'], ""));
            Image::from_layer(layer).write().to_file(&path).unwrap();
            let img = read_linear_rgb(&path, false).unwrap();
            assert_eq!((img.width, img.height), (w, h));
            for (i, t) in img.texels.iter().enumerate() {
                let want = Vec3::from(px(i % w, i / w).map(|v| f16::from_f32(v).to_f32()));
                assert!(
                    ((*t - want) / want).abs().max_element() <= tol,
                    "{compression:?} pixel {i}: {t} vs {want}"
                );
            }
        }
        std::fs::remove_dir_all(dir).ok();
    }
}
