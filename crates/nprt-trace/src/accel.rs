//! Ray-triangle intersection over the whole scene with obvhs's compressed wide BVH (chosen over
//! the `bvh` crate by `cargo bench --manifest-path bench/bvh/Cargo.toml`).

use std::time::Duration;

use glam::{Vec3, Vec3A};
use nprt_scene::Scene;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;

use crate::hittable::hittable;

/// A triangle laid out for Möller-Trumbore: v0, e1 = v0 − v1, e2 = v2 − v0, n = e1 × e2.
#[derive(Clone, Copy)]
pub(crate) struct Tri {
    pub v0: Vec3A,
    pub e1: Vec3A,
    pub e2: Vec3A,
    n: Vec3A,
}

/// Every triangle of `scene`, mesh after mesh, as obvhs builds over them.
pub(crate) fn scene_triangles(scene: &Scene) -> Vec<Triangle> {
    scene
        .meshes
        .iter()
        .flat_map(|mesh| {
            mesh.indices.iter().map(|t| {
                let p = t.map(|i| Vec3A::from(mesh.positions[i as usize]));
                Triangle {
                    v0: p[0],
                    v1: p[1],
                    v2: p[2],
                }
            })
        })
        .collect()
}

impl Tri {
    pub(crate) fn new(t: &Triangle) -> Self {
        let (e1, e2) = (t.v0 - t.v1, t.v2 - t.v0);
        Tri {
            v0: t.v0,
            e1,
            e2,
            n: e1.cross(e2),
        }
    }

    /// (t, b1, b2) with the hit at v0·(1−b1−b2) + v1·b1 + v2·b2, or None.
    #[inline(always)]
    fn intersect(&self, ray: &Ray) -> Option<(f32, f32, f32)> {
        let c = self.v0 - ray.origin;
        let r = ray.direction.cross(c);
        let det = self.n.dot(ray.direction);
        if det == 0.0 {
            return None;
        }
        let inv = 1.0 / det;
        let b1 = r.dot(self.e2) * inv;
        let b2 = r.dot(self.e1) * inv;
        if b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0 {
            return None;
        }
        let t = self.n.dot(c) * inv;
        (t > ray.tmin && t < ray.tmax).then_some((t, b1, b2))
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub mesh: u32,
    pub tri: u32,
    /// Barycentric weights of the triangle's second and third vertices.
    pub b1: f32,
    pub b2: f32,
}

pub struct Accel {
    bvh: CwBvh,
    /// In BVH leaf order, so traversal indexes them directly.
    tris: Vec<Tri>,
    /// (mesh, triangle) of each entry of `tris`.
    refs: Vec<(u32, u32)>,
}

/// obvhs inverts a `-0.0` direction component to −∞ but orders slabs by `d < 0`, which is false
/// for `-0.0`, so axis-aligned rays such as −Z would miss everything. Adding +0.0 turns −0 into +0.
fn bvh_ray(origin: Vec3, dir: Vec3, tmax: f32) -> Ray {
    Ray::new(origin.into(), Vec3A::from(dir) + Vec3A::ZERO, 0.0, tmax)
}

impl Accel {
    pub fn new(scene: &Scene) -> Self {
        let all = scene_triangles(scene);
        let all_refs: Vec<(u32, u32)> = scene
            .meshes
            .iter()
            .enumerate()
            .flat_map(|(mi, mesh)| (0..mesh.indices.len() as u32).map(move |ti| (mi as u32, ti)))
            .collect();
        let kept = hittable(&all);
        let tris: Vec<Triangle> = kept.iter().map(|&i| all[i as usize]).collect();
        let refs: Vec<(u32, u32)> = kept.iter().map(|&i| all_refs[i as usize]).collect();
        let bvh = build_cwbvh_from_tris(
            &tris,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let order = &bvh.primitive_indices;
        let tris = order.iter().map(|&i| Tri::new(&tris[i as usize])).collect();
        let refs = order.iter().map(|&i| refs[i as usize]).collect();
        Accel { bvh, tris, refs }
    }

    /// Closest hit along `origin + t·dir` for t in (0, tmax).
    pub fn intersect(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Option<Hit> {
        if self.tris.is_empty() {
            return None;
        }
        let ray = bvh_ray(origin, dir, tmax);
        let mut rh = RayHit::none();
        let mut best = (0usize, 0.0f32, 0.0f32);
        let mut closest = tmax;
        let found = self
            .bvh
            .ray_traverse(ray, &mut rh, |r, id| match self.tris[id].intersect(r) {
                Some((t, b1, b2)) if t < closest => {
                    closest = t;
                    best = (id, b1, b2);
                    t
                }
                _ => f32::INFINITY,
            });
        found.then(|| {
            let (mesh, tri) = self.refs[best.0];
            Hit {
                t: closest,
                mesh,
                tri,
                b1: best.1,
                b2: best.2,
            }
        })
    }

    /// Whether anything blocks `origin + t·dir` for t in (0, tmax).
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        if self.tris.is_empty() {
            return false;
        }
        let ray = bvh_ray(origin, dir, tmax);
        !self.bvh.ray_traverse_miss(ray, |r, id| {
            self.tris[id].intersect(r).map_or(f32::INFINITY, |h| h.0)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nprt_scene::{Material, Mesh};

    #[test]
    fn hits_report_distance_triangle_and_barycentrics() {
        let mut s = Scene::empty("t");
        let mut m = Mesh::rectangle();
        m.transform(glam::Mat4::from_translation(Vec3::new(0.0, 0.0, -2.0)));
        s.add(m, Material::diffuse("d", Vec3::ONE));
        s.add(
            Mesh::sphere(Vec3::new(5.0, 0.0, 0.0), 1.0, 16),
            Material::diffuse("d", Vec3::ONE),
        );
        let a = Accel::new(&s);
        let h = a
            .intersect(Vec3::new(0.2, 0.3, 0.0), -Vec3::Z, f32::INFINITY)
            .unwrap();
        assert!((h.t - 2.0).abs() < 1e-5);
        assert_eq!(h.mesh, 0);
        let mesh = &s.meshes[0];
        let t = mesh.indices[h.tri as usize].map(|i| mesh.positions[i as usize]);
        let p = t[0] * (1.0 - h.b1 - h.b2) + t[1] * h.b1 + t[2] * h.b2;
        assert!((p - Vec3::new(0.2, 0.3, -2.0)).length() < 1e-5, "{p}");
        assert!(a
            .intersect(Vec3::new(0.2, 0.3, 0.0), Vec3::Z, f32::INFINITY)
            .is_none());
        assert!(a.occluded(Vec3::ZERO, -Vec3::Z, 3.0));
        assert!(!a.occluded(Vec3::ZERO, -Vec3::Z, 1.5));
        // The sphere is found from the side, nearest face first.
        let h = a.intersect(Vec3::ZERO, Vec3::X, f32::INFINITY).unwrap();
        assert_eq!(h.mesh, 1);
        assert!((h.t - 4.0).abs() < 1e-2);
    }
}
