//! `<emitter>`: the environment (`envmap`, `constant`).

use anyhow::{anyhow, Context, Result};
use glam::{Mat3, Vec3};
use roxmltree::Node;

use crate::envmap::EnvMap;
use crate::texture::Texture;

use super::Ctx;

impl<'a> Ctx<'a> {
    pub(super) fn emitter(&mut self, node: Node<'a, 'a>) -> Result<()> {
        if self.lighting_replaced {
            return Ok(());
        }
        if self.scene.envmap.is_some() {
            return self.fail(node, "only one environment emitter is supported");
        }
        let map = match node.attribute("type").unwrap_or("") {
            "envmap" => {
                let filename = self
                    .string_prop(node, "filename")?
                    .ok_or_else(|| anyhow!("{}: missing 'filename'", self.at(node)))?;
                let path = self.path(node, &filename)?;
                let scale = self.float_prop(node, "scale", 1.0)?;
                EnvMap::load(&path, scale).with_context(|| self.at(node))?
            }
            "constant" => match self.texture_prop(node, "radiance", Vec3::ONE)? {
                Texture::Constant(c) => EnvMap::constant(c).with_context(|| self.at(node))?,
                _ => return self.fail(node, "constant emitter radiance must be a colour"),
            },
            other => {
                return self.fail(
                    node,
                    format!("unsupported emitter plugin '{other}' (supported: envmap, constant)"),
                )
            }
        };
        let to_world = match self.prop(node, "to_world") {
            Some(t) => Mat3::from_mat4(self.transform(t)?),
            None => Mat3::IDENTITY,
        };
        self.scene.envmap = Some(map.with_to_world(to_world));
        Ok(())
    }
}
