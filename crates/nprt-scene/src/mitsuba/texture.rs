//! Textures: `bitmap` and `checkerboard`, and the colour or texture a property names.

use std::sync::Arc;

use anyhow::{anyhow, Context, Result};
use glam::{Affine2, Vec2, Vec3};
use roxmltree::Node;

use crate::texture::{Bitmap, Texture};

use super::{Ctx, Named};

impl<'a> Ctx<'a> {
    /// A property that must be one colour (not a texture).
    pub(super) fn colour_prop(
        &mut self,
        node: Node<'a, 'a>,
        name: &str,
        default: Vec3,
    ) -> Result<Vec3> {
        match self.texture_prop(node, name, default)? {
            Texture::Constant(c) => Ok(c),
            _ => self.fail(node, format!("'{name}' must be a colour, not a texture")),
        }
    }

    /// A colour or texture property; `default` when absent.
    pub(super) fn texture_prop(
        &mut self,
        node: Node<'a, 'a>,
        name: &str,
        default: Vec3,
    ) -> Result<Texture> {
        let Some(p) = self.prop(node, name) else {
            return Ok(Texture::Constant(default));
        };
        match p.tag_name().name() {
            "rgb" => Ok(Texture::Constant(self.vec3_value(p, 0.0)?)),
            "float" => Ok(Texture::Constant(Vec3::splat(self.float_value(p)?))),
            "spectrum" => {
                let v = self.req(p, "value")?;
                if v.contains(':') {
                    return self.fail(p, "sampled spectra are not supported; give an <rgb> value");
                }
                Ok(Texture::Constant(self.vec3_value(p, 0.0)?))
            }
            "texture" => self.texture(p),
            "ref" => match self.named.get(&self.req(p, "id")?) {
                Some(Named::Texture(t)) => Ok(t.clone()),
                _ => self.fail(p, "does not refer to a texture declared earlier"),
            },
            other => self.fail(p, format!("<{other}> cannot give a colour")),
        }
    }

    pub(super) fn texture(&mut self, node: Node<'a, 'a>) -> Result<Texture> {
        let to_uv = match self.prop(node, "to_uv") {
            Some(t) => {
                let m = self.transform(t)?;
                Affine2::from_cols(
                    m.x_axis.truncate().truncate(),
                    m.y_axis.truncate().truncate(),
                    m.w_axis.truncate().truncate(),
                )
            }
            None => Affine2::IDENTITY,
        };
        // Mitsuba 0.x placed bitmaps by uoffset/voffset/uscale/vscale.
        let to_uv = if self.legacy {
            let scale = Vec2::new(
                self.float_prop(node, "uscale", 1.0)?,
                self.float_prop(node, "vscale", 1.0)?,
            );
            let offset = Vec2::new(
                self.float_prop(node, "uoffset", 0.0)?,
                self.float_prop(node, "voffset", 0.0)?,
            );
            Affine2::from_scale(scale) * Affine2::from_translation(offset) * to_uv
        } else {
            to_uv
        };
        match node.attribute("type").unwrap_or("") {
            "bitmap" => {
                let filename = self
                    .string_prop(node, "filename")?
                    .ok_or_else(|| anyhow!("{}: missing 'filename'", self.at(node)))?;
                let path = self.path(node, &filename)?;
                let raw = self.bool_prop(node, "raw", false)?;
                if let Some(w) = self.string_prop(node, "wrap_mode")? {
                    if w != "repeat" {
                        self.scene.warnings.push(format!(
                            "{}: wrap_mode '{w}' is traced as 'repeat'",
                            self.at(node)
                        ));
                    }
                }
                let key = (path.clone(), raw);
                let image = match self.bitmaps.get(&key) {
                    Some(b) => b.clone(),
                    None => {
                        let b = Arc::new(Bitmap::load(&path, raw).with_context(|| self.at(node))?);
                        self.bitmaps.insert(key, b.clone());
                        b
                    }
                };
                Ok(Texture::Bitmap {
                    image,
                    to_uv,
                    factor: Vec3::ONE,
                })
            }
            "checkerboard" => {
                let c0 = self.texture_prop(node, "color0", Vec3::splat(0.4))?;
                let c1 = self.texture_prop(node, "color1", Vec3::splat(0.2))?;
                match (c0, c1) {
                    (Texture::Constant(color0), Texture::Constant(color1)) => {
                        Ok(Texture::Checkerboard {
                            color0,
                            color1,
                            to_uv,
                        })
                    }
                    _ => self.fail(node, "checkerboard colours must be constants"),
                }
            }
            other => self.fail(
                node,
                format!("unsupported texture plugin '{other}' (supported: bitmap, checkerboard)"),
            ),
        }
    }
}
