//! Spatially varying material inputs: constants, bitmaps and Mitsuba's checkerboard.

use std::path::Path;
use std::sync::Arc;

use anyhow::{Context, Result};
use glam::{Affine2, Vec2, Vec3};

use crate::color::luminance;
use crate::image_file::{read_linear_rgb, LinearImage};

/// A linear-RGB image sampled with bilinear filtering and repeat wrapping (Mitsuba's and glTF's
/// defaults).
#[derive(Debug)]
pub struct Bitmap {
    pub width: usize,
    pub height: usize,
    /// Row-major, top row first, linear RGB.
    pub texels: Vec<Vec3>,
}

impl From<LinearImage> for Bitmap {
    fn from(img: LinearImage) -> Self {
        Bitmap {
            width: img.width,
            height: img.height,
            texels: img.texels,
        }
    }
}

impl Bitmap {
    /// Reads a PNG/JPEG (sRGB-decoded unless `raw`) or an EXR/HDR (always linear) image.
    pub fn load(path: &Path, raw: bool) -> Result<Self> {
        let img = read_linear_rgb(path, raw).context("cannot read texture")?;
        Ok(Self::from(img))
    }

    fn texel(&self, x: i64, y: i64) -> Vec3 {
        let x = x.rem_euclid(self.width as i64) as usize;
        let y = y.rem_euclid(self.height as i64) as usize;
        self.texels[y * self.width + x]
    }

    /// Bilinear lookup; uv (0,0) is the top-left corner of the image (glTF and Mitsuba 3 agree).
    pub fn eval(&self, uv: Vec2) -> Vec3 {
        let px = uv.x * self.width as f32 - 0.5;
        let py = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (px.floor(), py.floor());
        let (fx, fy) = (px - x0, py - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), fx);
        let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }
}

/// A colour (or scalar, in `.x`) that may vary over a surface's uv coordinates.
#[derive(Clone, Debug)]
pub enum Texture {
    Constant(Vec3),
    /// `factor * bitmap(to_uv(uv))`.
    Bitmap {
        image: Arc<Bitmap>,
        to_uv: Affine2,
        factor: Vec3,
    },
    /// Mitsuba's checkerboard: `color0` where the fractional parts of u and v fall on the same
    /// side of ½, else `color1`.
    Checkerboard {
        color0: Vec3,
        color1: Vec3,
        to_uv: Affine2,
    },
}

impl Texture {
    pub fn constant(v: f32) -> Self {
        Texture::Constant(Vec3::splat(v))
    }

    pub fn eval(&self, uv: Vec2) -> Vec3 {
        match self {
            Texture::Constant(c) => *c,
            Texture::Bitmap {
                image,
                to_uv,
                factor,
            } => *factor * image.eval(to_uv.transform_point2(uv)),
            Texture::Checkerboard {
                color0,
                color1,
                to_uv,
            } => {
                let p = to_uv.transform_point2(uv);
                let f = p - p.floor();
                if (f.x > 0.5) == (f.y > 0.5) {
                    *color0
                } else {
                    *color1
                }
            }
        }
    }

    /// Mean over the texture as Mitsuba 3's `mean()` in RGB mode: the channels' mean for a
    /// colour, the texels' mean luminance for a bitmap (times its factor's mean).
    pub fn mean(&self) -> f32 {
        let channels = |c: Vec3| (c.x + c.y + c.z) / 3.0;
        match self {
            Texture::Constant(c) => channels(*c),
            Texture::Bitmap { image, factor, .. } => {
                let sum: f64 = image.texels.iter().map(|t| luminance(*t) as f64).sum();
                channels(*factor) * (sum / image.texels.len().max(1) as f64) as f32
            }
            Texture::Checkerboard { color0, color1, .. } => {
                0.5 * (channels(*color0) + channels(*color1))
            }
        }
    }

    pub fn is_constant(&self) -> bool {
        matches!(self, Texture::Constant(_))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bitmap_centres_and_wrap() {
        let b = Bitmap {
            width: 2,
            height: 1,
            texels: vec![Vec3::ZERO, Vec3::ONE],
        };
        assert_eq!(b.eval(Vec2::new(0.25, 0.5)), Vec3::ZERO);
        assert_eq!(b.eval(Vec2::new(0.75, 0.5)), Vec3::ONE);
        // Halfway between the last and (wrapped) first texel.
        assert!((b.eval(Vec2::new(1.0, 0.5)).x - 0.5).abs() < 1e-6);
    }

    #[test]
    fn checkerboard_matches_mitsuba_rule() {
        let t = Texture::Checkerboard {
            color0: Vec3::ONE,
            color1: Vec3::ZERO,
            to_uv: Affine2::IDENTITY,
        };
        assert_eq!(t.eval(Vec2::new(0.25, 0.25)), Vec3::ONE);
        assert_eq!(t.eval(Vec2::new(0.75, 0.25)), Vec3::ZERO);
        assert_eq!(t.eval(Vec2::new(0.75, 0.75)), Vec3::ONE);
    }
}
