//! A binary BVH over a scene's triangles laid out flat for a GPU's stack walk (nprt-render's
//! path tracer on the device): obvhs's Bvh2, whose inner nodes keep their two children side by
//! side, as eight words a node, and its leaves' triangles in leaf order, each laid out for
//! Möller-Trumbore as [`crate::Accel`] lays its own, so that a test reads one record instead of
//! following indices to the vertices. The CPU's Accel stays on the wide BVH, which walks faster
//! on a CPU; both answer the same closest hit.

use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;

use crate::accel::Tri;
use crate::hittable::hittable;

/// Words per node: `[min (3 f32), triangle count, max (3 f32), first]` with `first` the first
/// child's node (inner nodes: count 0; the second child follows it) or a leaf's first entry of
/// [`FlatBvh::triangles`].
pub const NODE_WORDS: usize = 8;

/// Words per triangle record: `[v0 (3 f32), the triangle's index among the scene's (counted
/// mesh after mesh), e1 = v0 − v1 (3 f32), 0, e2 = v2 − v0 (3 f32), 0]`.
pub const TRIANGLE_WORDS: usize = 12;

pub struct FlatBvh {
    /// The nodes, the root first, f32 fields as their bits.
    pub nodes: Vec<u32>,
    /// The leaves' triangles in leaf order, [`TRIANGLE_WORDS`] each.
    pub triangles: Vec<u32>,
}

impl FlatBvh {
    /// Over triangles given by their corners, in the scene's order (mesh after mesh), which
    /// the records' indices count.
    pub fn from_corners(corners: impl Iterator<Item = [Vec3; 3]>) -> Self {
        let all: Vec<Triangle> = corners
            .map(|[v0, v1, v2]| Triangle {
                v0: v0.into(),
                v1: v1.into(),
                v2: v2.into(),
            })
            .collect();
        // Each record keeps its index among the scene's triangles (`kept[i]`).
        let kept = hittable(&all);
        let tris: Vec<Triangle> = kept.iter().map(|&i| all[i as usize]).collect();
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
        let mut triangles = Vec::with_capacity(TRIANGLE_WORDS * tris.len());
        for &i in &bvh.primitive_indices {
            let t = Tri::new(&tris[i as usize]);
            let words = |v: Vec3A, w: u32| {
                let [x, y, z] = v.to_array().map(f32::to_bits);
                [x, y, z, w]
            };
            triangles.extend(words(t.v0, kept[i as usize]));
            triangles.extend(words(t.e1, 0));
            triangles.extend(words(t.e2, 0));
        }
        FlatBvh { nodes, triangles }
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
        let bvh = FlatBvh::from_corners(corners.iter().copied());
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
            for entry in first..first + count as usize {
                let record = &bvh.triangles[TRIANGLE_WORDS * entry..TRIANGLE_WORDS * (entry + 1)];
                let t = record[3];
                let v0 = Vec3::new(
                    f32::from_bits(record[0]),
                    f32::from_bits(record[1]),
                    f32::from_bits(record[2]),
                );
                assert_eq!(v0, corners[t as usize][0], "the record's first vertex");
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
