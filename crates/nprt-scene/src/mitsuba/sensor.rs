//! `<sensor>`: the perspective camera, its film and sampler.

use anyhow::Result;
use glam::Mat4;
use roxmltree::Node;

use crate::camera::{Camera, FovAxis};

use super::Ctx;

impl<'a> Ctx<'a> {
    pub(super) fn sensor(&mut self, node: Node<'a, 'a>) -> Result<()> {
        if node.attribute("type") != Some("perspective") {
            return self.fail(node, "unsupported sensor (only 'perspective')");
        }
        let to_world = match self.prop(node, "to_world") {
            Some(t) => self.transform(t)?,
            None => Mat4::IDENTITY,
        };
        let fov_axis = match self
            .string_prop(node, "fov_axis")?
            .as_deref()
            .unwrap_or("x")
        {
            "x" => FovAxis::X,
            "y" => FovAxis::Y,
            "diagonal" => FovAxis::Diagonal,
            "smaller" => FovAxis::Smaller,
            "larger" => FovAxis::Larger,
            other => return self.fail(node, format!("unknown fov_axis '{other}'")),
        };
        if self.prop(node, "focal_length").is_some() {
            return self.fail(node, "focal_length is not supported; give fov");
        }
        let fov_deg = self.float_prop(node, "fov", 0.0)?;
        if !(fov_deg > 0.0 && fov_deg < 180.0) {
            return self.fail(node, "needs a 'fov' between 0 and 180 degrees");
        }
        let (mut width, mut height) = (768, 576);
        for child in node.children().filter(Node::is_element) {
            match child.tag_name().name() {
                "film" => {
                    if child.attribute("type") != Some("hdrfilm") {
                        return self.fail(child, "unsupported film (only 'hdrfilm')");
                    }
                    width = self.int_prop(child, "width")?.unwrap_or(768).max(1) as u32;
                    height = self.int_prop(child, "height")?.unwrap_or(576).max(1) as u32;
                    if self.prop(child, "crop_width").is_some()
                        || self.prop(child, "crop_offset_x").is_some()
                    {
                        return self.fail(child, "film crop windows are not supported");
                    }
                    self.rfilter_box = child
                        .children()
                        .any(|r| r.has_tag_name("rfilter") && r.attribute("type") == Some("box"));
                }
                "sampler" => {
                    if let Some(n) = self.int_prop(child, "sample_count")? {
                        self.scene.spp = Some(n.max(1) as u32);
                    }
                }
                _ => {}
            }
        }
        self.scene.camera = Some(Camera {
            to_world,
            fov_deg,
            fov_axis,
            width,
            height,
        });
        Ok(())
    }
}
