//! Triangle meshes in world space, and the analytic shapes Mitsuba 3 builds in, tessellated.

use glam::{Mat3, Mat4, Vec2, Vec3};

#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals; empty means flat shading with the geometric normal.
    pub normals: Vec<Vec3>,
    /// Per-vertex texture coordinates; empty means (0,0) everywhere.
    pub uvs: Vec<Vec2>,
    pub indices: Vec<[u32; 3]>,
    /// Index into the scene's materials.
    pub material: usize,
}

impl Mesh {
    /// Applies `m` to positions and (by its inverse transpose) to normals.
    pub fn transform(&mut self, m: Mat4) {
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        let n = Mat3::from_mat4(m).inverse().transpose();
        for v in &mut self.normals {
            *v = (n * *v).normalize_or_zero();
        }
    }

    /// Smooth vertex normals weighted by the angle each face makes at the vertex (Mitsuba 3's
    /// choice for meshes that come without normals).
    pub fn compute_vertex_normals(&mut self) {
        let mut normals = vec![Vec3::ZERO; self.positions.len()];
        for tri in &self.indices {
            let p = tri.map(|i| self.positions[i as usize]);
            let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
            for k in 0..3 {
                let d0 = (p[(k + 1) % 3] - p[k]).normalize_or_zero();
                let d1 = (p[(k + 2) % 3] - p[k]).normalize_or_zero();
                normals[tri[k] as usize] += n * d0.dot(d1).clamp(-1.0, 1.0).acos();
            }
        }
        self.normals = normals
            .into_iter()
            .map(|n| n.normalize_or(Vec3::Y))
            .collect();
    }

    /// Reverses triangle winding, which flips geometric normals only.
    pub fn reverse_winding(&mut self) {
        for t in &mut self.indices {
            t.swap(1, 2);
        }
    }

    /// Flips geometric and shading normals (Mitsuba's `flip_normals`).
    pub fn flip_normals(&mut self) {
        self.reverse_winding();
        for n in &mut self.normals {
            *n = -*n;
        }
    }

    /// Checks indices and attribute lengths; `what` names the source in the error.
    pub fn validate(&self, what: &str) -> anyhow::Result<()> {
        let n = self.positions.len();
        if self.indices.is_empty() {
            anyhow::bail!("{what}: mesh '{}' has no triangles", self.name);
        }
        if let Some(t) = self
            .indices
            .iter()
            .find(|t| t.iter().any(|&i| i as usize >= n))
        {
            anyhow::bail!(
                "{what}: mesh '{}' has face {t:?} referring past its {n} vertices",
                self.name
            );
        }
        if (!self.normals.is_empty() && self.normals.len() != n)
            || (!self.uvs.is_empty() && self.uvs.len() != n)
        {
            anyhow::bail!(
                "{what}: mesh '{}' has attribute arrays of inconsistent length",
                self.name
            );
        }
        if self.positions.iter().any(|p| !p.is_finite()) {
            anyhow::bail!(
                "{what}: mesh '{}' has non-finite vertex positions",
                self.name
            );
        }
        Ok(())
    }

    /// Mitsuba's `rectangle`: [-1,1]² in the z=0 plane facing +Z, uv = (x+1)/2, (y+1)/2.
    pub fn rectangle() -> Self {
        let positions = vec![
            Vec3::new(-1., -1., 0.),
            Vec3::new(1., -1., 0.),
            Vec3::new(1., 1., 0.),
            Vec3::new(-1., 1., 0.),
        ];
        Mesh {
            name: "rectangle".into(),
            uvs: positions
                .iter()
                .map(|p| Vec2::new(p.x * 0.5 + 0.5, p.y * 0.5 + 0.5))
                .collect(),
            positions,
            normals: vec![Vec3::Z; 4],
            indices: vec![[0, 1, 2], [0, 2, 3]],
            material: 0,
        }
    }

    /// Mitsuba's `cube`: [-1,1]³ with flat, outward faces.
    pub fn cube() -> Self {
        let mut m = Mesh {
            name: "cube".into(),
            ..Default::default()
        };
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let mut rect = Mesh::rectangle();
                // Rotate +Z onto the face normal, then push the face out to the cube's side.
                let n = Vec3::AXES[axis] * sign;
                let rot = Mat4::from_quat(glam::Quat::from_rotation_arc(Vec3::Z, n));
                rect.transform(Mat4::from_translation(n) * rot);
                m.append(rect);
            }
        }
        m
    }

    /// Mitsuba's `sphere` (centre, radius) as a UV sphere with exact normals; uv has the pole on
    /// local +Z as Mitsuba's.
    pub fn sphere(center: Vec3, radius: f32, segments: u32) -> Self {
        let (nu, nv) = (2 * segments, segments);
        let mut m = Mesh {
            name: "sphere".into(),
            ..Default::default()
        };
        for j in 0..=nv {
            let theta = j as f32 / nv as f32 * std::f32::consts::PI;
            for i in 0..=nu {
                let phi = i as f32 / nu as f32 * 2.0 * std::f32::consts::PI;
                let n = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                );
                m.positions.push(center + radius * n);
                m.normals.push(n);
                m.uvs
                    .push(Vec2::new(i as f32 / nu as f32, j as f32 / nv as f32));
            }
        }
        let row = nu + 1;
        for j in 0..nv {
            for i in 0..nu {
                let (a, b, c, d) = (
                    j * row + i,
                    j * row + i + 1,
                    (j + 1) * row + i,
                    (j + 1) * row + i + 1,
                );
                // Outward winding; skip the degenerate triangles at the poles.
                if j != 0 {
                    m.indices.push([a, d, b]);
                }
                if j != nv - 1 {
                    m.indices.push([a, c, d]);
                }
            }
        }
        m
    }

    /// Appends another mesh's triangles (keeping this mesh's material).
    pub fn append(&mut self, other: Mesh) {
        let base = self.positions.len() as u32;
        let same_attributes = self.normals.is_empty() == other.normals.is_empty()
            && self.uvs.is_empty() == other.uvs.is_empty();
        assert!(
            same_attributes || self.positions.is_empty(),
            "appending meshes with different attributes"
        );
        self.positions.extend(other.positions);
        self.normals.extend(other.normals);
        self.uvs.extend(other.uvs);
        self.indices
            .extend(other.indices.into_iter().map(|t| t.map(|i| i + base)));
    }

    pub fn area(&self) -> f32 {
        self.indices
            .iter()
            .map(|t| {
                let p = t.map(|i| self.positions[i as usize]);
                0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_have_expected_area() {
        assert!((Mesh::rectangle().area() - 4.0).abs() < 1e-5);
        assert!((Mesh::cube().area() - 24.0).abs() < 1e-4);
        let s = Mesh::sphere(Vec3::ZERO, 2.0, 64);
        let exact = 4.0 * std::f32::consts::PI * 4.0;
        assert!((s.area() - exact).abs() / exact < 2e-3);
    }

    #[test]
    fn cube_faces_point_outwards() {
        let c = Mesh::cube();
        for t in &c.indices {
            let p = t.map(|i| c.positions[i as usize]);
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            let centre = (p[0] + p[1] + p[2]) / 3.0;
            assert!(n.dot(centre) > 0.0);
            assert!(c.normals[t[0] as usize].dot(centre) > 0.0);
        }
    }

    #[test]
    fn computed_normals_of_a_flat_patch_are_its_normal() {
        let mut r = Mesh::rectangle();
        r.normals.clear();
        r.compute_vertex_normals();
        assert!(r.normals.iter().all(|n| (*n - Vec3::Z).length() < 1e-6));
    }
}
