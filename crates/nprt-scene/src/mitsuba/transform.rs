//! `<transform>`: translate, rotate, scale, matrix and lookat, composed in document order.

use anyhow::Result;
use glam::{Mat3, Mat4, Vec3};
use roxmltree::Node;

use crate::camera::look_at;

use super::Ctx;

impl<'a> Ctx<'a> {
    pub(super) fn transform(&self, node: Node) -> Result<Mat4> {
        let mut m = Mat4::IDENTITY;
        for t in node.children().filter(Node::is_element) {
            let step = match t.tag_name().name() {
                "translate" => Mat4::from_translation(self.vec3_value(t, 0.0)?),
                "scale" => Mat4::from_scale(self.vec3_value(t, 1.0)?),
                "rotate" => {
                    let axis = self.vec3_value(t, 0.0)?;
                    let angle: f32 = self
                        .req(t, "angle")?
                        .trim()
                        .parse()
                        .or_else(|_| self.fail(t, "angle is not a number"))?;
                    if axis.length_squared() == 0.0 {
                        return self.fail(t, "rotation axis is zero");
                    }
                    Mat4::from_axis_angle(axis.normalize(), angle.to_radians())
                }
                "matrix" => {
                    let v = self.numbers(t, &self.req(t, "value")?)?;
                    match v.len() {
                        16 => Mat4::from_cols_array(&v.try_into().unwrap()).transpose(),
                        9 => Mat4::from_mat3(
                            Mat3::from_cols_array(&v.try_into().unwrap()).transpose(),
                        ),
                        n => {
                            return self.fail(t, format!("a matrix needs 9 or 16 values, got {n}"))
                        }
                    }
                }
                "lookat" | "lookAt" => {
                    let get = |k: &str| -> Result<Vec3> {
                        let v = self.numbers(t, &self.req(t, k)?)?;
                        if v.len() != 3 {
                            return self.fail(t, format!("'{k}' needs 3 numbers"));
                        }
                        Ok(Vec3::new(v[0], v[1], v[2]))
                    };
                    let up = if t.attribute("up").is_some() {
                        get("up")?
                    } else {
                        Vec3::Y
                    };
                    look_at(get("origin")?, get("target")?, up)
                }
                other => return self.fail(t, format!("unknown transform operation <{other}>")),
            };
            m = step * m;
        }
        Ok(m)
    }
}
