//! A binary BVH over a scene's triangles laid out flat for a GPU's stack walk (nprt-render's
//! path tracer on the device): obvhs's Bvh2, whose inner nodes keep their two children side by
//! side, as eight words a node. The CPU's [`crate::Accel`] stays on the wide BVH, which walks
//! faster on a CPU; both answer the same closest hit.

use std::time::Duration;

use glam::Vec3A;
use nprt_scene::Scene;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;

/// Words per node: `[min (3 f32), triangle count, max (3 f32), first]` with `first` the first
/// child's node (inner nodes: count 0; the second child follows it) or a leaf's first entry of
/// [`FlatBvh::triangles`].
pub const NODE_WORDS: usize = 8;

pub struct FlatBvh {
    /// The nodes, the root first, f32 fields as their bits.
    pub nodes: Vec<u32>,
    /// Leaves' triangles, as indices into the scene's triangles counted mesh after mesh.
    pub triangles: Vec<u32>,
}

impl FlatBvh {
    pub fn new(scene: &Scene) -> Self {
        let tris: Vec<Triangle> = scene
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
            .collect();
        if tris.is_empty() {
            // A placeholder root: a walk must not start on a scene without triangles.
            return FlatBvh {
                nodes: vec![0; NODE_WORDS],
                triangles: Vec::new(),
            };
        }
        let bvh = build_bvh2_from_tris(
            &tris,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let mut nodes = Vec::with_capacity(NODE_WORDS * bvh.nodes.len());
        for n in &bvh.nodes {
            nodes.extend(n.aabb.min.to_array().map(f32::to_bits));
            nodes.push(n.prim_count);
            nodes.extend(n.aabb.max.to_array().map(f32::to_bits));
            nodes.push(n.first_index);
        }
        FlatBvh {
            nodes,
            triangles: bvh.primitive_indices,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Every triangle sits in exactly one leaf, inside that leaf's box and every box above it.
    #[test]
    fn every_triangle_is_in_one_leaf_inside_its_ancestors_boxes() {
        let scene = nprt_scene::load_scene("builtin:room", &Default::default()).unwrap();
        let corners: Vec<[Vec3; 3]> = scene
            .meshes
            .iter()
            .flat_map(|m| m.indices.iter().map(|t| t.map(|i| m.positions[i as usize])))
            .collect();
        let bvh = FlatBvh::new(&scene);
        let node = |k: usize| {
            let w = &bvh.nodes[NODE_WORDS * k..NODE_WORDS * (k + 1)];
            let v = |o: usize| {
                Vec3::new(
                    f32::from_bits(w[o]),
                    f32::from_bits(w[o + 1]),
                    f32::from_bits(w[o + 2]),
                )
            };
            (v(0), w[3], v(4), w[7] as usize)
        };
        let mut seen = vec![0u32; corners.len()];
        // (node, the boxes above it).
        let mut stack = vec![(0usize, Vec::<(Vec3, Vec3)>::new())];
        while let Some((k, mut boxes)) = stack.pop() {
            let (lo, count, hi, first) = node(k);
            boxes.push((lo, hi));
            if count == 0 {
                stack.push((first, boxes.clone()));
                stack.push((first + 1, boxes));
                continue;
            }
            for &t in &bvh.triangles[first..first + count as usize] {
                seen[t as usize] += 1;
                for (lo, hi) in &boxes {
                    for p in corners[t as usize] {
                        assert!(p.cmpge(*lo - 1e-5).all() && p.cmple(*hi + 1e-5).all());
                    }
                }
            }
        }
        assert!(seen.iter().all(|&n| n == 1), "each triangle once");
    }
}
