//! `<shape>`: meshes from files and the analytic shapes, with their BSDFs and area emitters.

use anyhow::{anyhow, Context, Result};
use glam::Vec3;
use roxmltree::Node;

use crate::material::Material;
use crate::mesh::Mesh;
use crate::mesh_io::load_mesh;

use super::{Ctx, Named};

/// Tessellation of Mitsuba's analytic `sphere` (segments around the pole axis = 2×).
const SPHERE_SEGMENTS: u32 = 96;

impl<'a> Ctx<'a> {
    pub(super) fn shape(&mut self, node: Node<'a, 'a>) -> Result<()> {
        let ty = node.attribute("type").unwrap_or("");
        let mut mesh = match ty {
            "obj" | "ply" => {
                let filename = self.string_prop(node, "filename")?.ok_or_else(|| anyhow!("{}: missing 'filename'", self.at(node)))?;
                let path = self.path(node, &filename)?;
                load_mesh(&path, self.bool_prop(node, "face_normals", false)?).with_context(|| self.at(node))?
            }
            "rectangle" => Mesh::rectangle(),
            "cube" => Mesh::cube(),
            "sphere" => {
                let center = match self.prop(node, "center") {
                    Some(p) => self.vec3_value(p, 0.0)?,
                    None => Vec3::ZERO,
                };
                Mesh::sphere(center, self.float_prop(node, "radius", 1.0)?, SPHERE_SEGMENTS)
            }
            other => return self.fail(node, format!("unsupported shape plugin '{other}' (supported: obj, ply, rectangle, cube, sphere)")),
        };
        if let Some(t) = self.prop(node, "to_world") {
            let m = self.transform(t)?;
            mesh.transform(m);
            if m.determinant() < 0.0 {
                mesh.reverse_winding();
            }
        }
        if self.bool_prop(node, "flip_normals", false)? {
            mesh.flip_normals();
        }
        let mut material = None;
        for child in node.children().filter(Node::is_element) {
            match child.tag_name().name() {
                "bsdf" => material = Some(self.bsdf(child)?),
                "ref" => match self.named.get(&self.req(child, "id")?) {
                    Some(Named::Material(m)) => material = Some(*m),
                    _ => return self.fail(child, "does not refer to a BSDF declared earlier"),
                },
                "emitter" => {
                    self.scene.warnings.push(format!(
                        "{}: removed this shape: it carries an area emitter, and nprt lights scenes by the environment only (such shapes are usually light portals in a window)",
                        self.at(node)
                    ));
                    return Ok(());
                }
                _ => {}
            }
        }
        mesh.material = match material {
            Some(m) => m,
            None => {
                // Mitsuba's default BSDF: one-sided diffuse, reflectance 0.5.
                let mut m = Material::diffuse("default", Vec3::splat(0.5));
                m.two_sided = false;
                self.scene.materials.push(m);
                self.scene.materials.len() - 1
            }
        };
        mesh.name = format!("{} ({ty})", self.at(node));
        self.scene.meshes.push(mesh);
        Ok(())
    }
}
