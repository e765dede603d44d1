//! Spatially varying material inputs: constants, bitmaps and Mitsuba's checkerboard.

use std::path::Path;
use std::sync::Arc;

use anyhow::{Context, Result};
use glam::{Affine2, Vec2, Vec3};

use crate::color::luminance;
use nprt_io::{read_linear_rgb, LinearImage};

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

    /// The texel at or before `uv` (texel centres at half-integers) and the weights of the
    /// next one in x and y.
    fn bilinear(&self, uv: Vec2) -> (i64, i64, f32, f32) {
        let px = uv.x * self.width as f32 - 0.5;
        let py = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (px.floor(), py.floor());
        (x0 as i64, y0 as i64, px - x0, py - y0)
    }

    /// Bilinear lookup; uv (0,0) is the top-left corner of the image (glTF and Mitsuba 3 agree).
    pub fn eval(&self, uv: Vec2) -> Vec3 {
        let (x0, y0, fx, fy) = self.bilinear(uv);
        let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), fx);
        let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }

    /// Gradient of the bilinearly interpolated luminance, per texel in x and y, at texture
    /// coordinates `uv` (Mitsuba 3's `eval_1_grad` before its uv transform and resolution).
    fn luminance_gradient(&self, uv: Vec2) -> Vec2 {
        let (x0, y0, fx, fy) = self.bilinear(uv);
        let f = |dx, dy| luminance(self.texel(x0 + dx, y0 + dy));
        let (f00, f10, f01, f11) = (f(0, 0), f(1, 0), f(0, 1), f(1, 1));
        Vec2::new(
            (1.0 - fy) * (f10 - f00) + fy * (f11 - f01),
            (1.0 - fx) * (f01 - f00) + fx * (f11 - f10),
        )
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

    /// This texture with every value it can give held to [0, 1] (what a reflectance or a
    /// transmittance may be), or None where it gives none outside.
    pub fn clamped_to_unit(&self) -> Option<Texture> {
        let unit = |v: Vec3| v.clamp(Vec3::ZERO, Vec3::ONE);
        let outside = |v: Vec3| unit(v) != v;
        match self {
            Texture::Constant(c) => outside(*c).then(|| Texture::Constant(unit(*c))),
            Texture::Checkerboard {
                color0,
                color1,
                to_uv,
            } => (outside(*color0) || outside(*color1)).then(|| Texture::Checkerboard {
                color0: unit(*color0),
                color1: unit(*color1),
                to_uv: *to_uv,
            }),
            Texture::Bitmap {
                image,
                to_uv,
                factor,
            } => {
                let values = image.texels.iter().map(|t| *t * *factor);
                values.clone().any(outside).then(|| Texture::Bitmap {
                    image: Arc::new(Bitmap {
                        width: image.width,
                        height: image.height,
                        texels: values.map(unit).collect(),
                    }),
                    to_uv: *to_uv,
                    factor: Vec3::ONE,
                })
            }
        }
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

    /// Gradient of the luminance with respect to the surface's uv, as Mitsuba 3's `eval_1_grad`
    /// (what a bump map's height field is read with): a bitmap's bilinear derivative through
    /// its uv transform, zero for constants and (piecewise constant) checkerboards.
    pub fn luminance_gradient(&self, uv: Vec2) -> Vec2 {
        match self {
            Texture::Bitmap {
                image,
                to_uv,
                factor,
            } => {
                let d = image.luminance_gradient(to_uv.transform_point2(uv));
                // Mitsuba applies the transform's transpose, then the resolution: the true
                // derivative where the transform only scales and shifts, as Mitsuba's own
                // otherwise (rotated uv on a non-square image), which we follow.
                let m = to_uv.matrix2;
                Vec2::new(m.x_axis.dot(d), m.y_axis.dot(d))
                    * Vec2::new(image.width as f32, image.height as f32)
                    * luminance(*factor)
            }
            Texture::Constant(_) | Texture::Checkerboard { .. } => Vec2::ZERO,
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

    /// The gradient is the derivative of `eval`'s luminance, through a uv scale and shift.
    #[test]
    fn luminance_gradient_is_the_derivative_of_the_lookup() {
        let texels = (0..35)
            .map(|i| Vec3::splat(((i * 37) % 11) as f32 / 11.0) * Vec3::new(1.0, 0.5, 2.0))
            .collect();
        let t = Texture::Bitmap {
            image: Arc::new(Bitmap {
                width: 7,
                height: 5,
                texels,
            }),
            to_uv: Affine2::from_scale_angle_translation(
                Vec2::new(2.0, -3.0),
                0.0,
                Vec2::new(0.2, 0.1),
            ),
            factor: Vec3::splat(1.5),
        };
        let h = 1e-4;
        for uv in [
            Vec2::new(0.31, 0.77),
            Vec2::new(0.12, 0.05),
            Vec2::new(0.66, 0.43),
        ] {
            let f = |uv: Vec2| luminance(t.eval(uv)) as f64;
            let fd = Vec2::new(
                ((f(uv + Vec2::X * h) - f(uv - Vec2::X * h)) / (2.0 * h as f64)) as f32,
                ((f(uv + Vec2::Y * h) - f(uv - Vec2::Y * h)) / (2.0 * h as f64)) as f32,
            );
            let g = t.luminance_gradient(uv);
            assert!(
                (g - fd).length() < 1e-2 * fd.length().max(1.0),
                "{g} vs {fd}"
            );
        }
        assert_eq!(
            Texture::constant(0.3).luminance_gradient(Vec2::ONE),
            Vec2::ZERO
        );
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
