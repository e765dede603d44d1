//! Which of a scene's triangles the BVH builders are given: those a ray can hit, each place in
//! space once. A triangle of zero area is never hit (Möller-Trumbore's determinant is 0), and
//! a coincident copy of an earlier one is hit at the same distance, so neither changes an
//! image; but obvhs's builder merges identical boxes one by one, so many of them made it
//! recurse once per triangle (a shape scaled by 0 or 10⁻³⁰: a stack overflow, found by the
//! `scene_geometry` fuzz target) or slow down without end (300 copies of one sphere ran past 2
//! minutes where 100 distinct spheres took 5 s). Of coincident copies the first, in scene
//! order, is kept: which one a ray would hit is otherwise undefined.

use obvhs::triangle::Triangle;

/// Indices into `tris` of the triangles to build over, in order.
pub fn hittable(tris: &[Triangle]) -> Vec<u32> {
    // The three corners' bits, sorted: equal for any copy of a triangle, whatever its order.
    let keys: Vec<[[u32; 3]; 3]> = tris
        .iter()
        .map(|t| {
            let mut corners = [t.v0, t.v1, t.v2].map(|v| v.to_array().map(f32::to_bits));
            corners.sort_unstable();
            corners
        })
        .collect();
    let mut order: Vec<u32> = (0..tris.len() as u32)
        .filter(|&i| {
            let t = &tris[i as usize];
            (t.v1 - t.v0).cross(t.v2 - t.v0) != glam::Vec3A::ZERO
        })
        .collect();
    // Sorted by corners, then index: each run of copies starts with the earliest.
    order.sort_unstable_by_key(|&i| (keys[i as usize], i));
    order.dedup_by_key(|i| keys[*i as usize]);
    order.sort_unstable();
    order
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3A;

    fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> Triangle {
        Triangle {
            v0: Vec3A::from(a),
            v1: Vec3A::from(b),
            v2: Vec3A::from(c),
        }
    }

    /// Zero-area triangles and later copies (in any corner order) are left out; the first of
    /// each place and every distinct triangle stay, in order.
    #[test]
    fn zero_area_and_later_copies_are_left_out() {
        let (o, x, y) = ([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let tris = [
            tri(o, o, o),
            tri(o, x, y),
            tri(o, x, [2.0, 0.0, 0.0]),
            tri(y, o, x),
            tri(o, x, [0.0, 1.0, 1e-7]),
            tri([1e-30; 3], [0.0; 3], [1e-30, 0.0, 0.0]),
            tri(o, x, y),
        ];
        assert_eq!(hittable(&tris), vec![1, 4]);
    }
}
