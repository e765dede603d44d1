// The hash grid's lookup, shared by the kernels that encode positions and that train the
// tables (each kernel's source is this file followed by its own): at each level the 8 vertices
// of the cell around a position with their trilinear weights, indexed directly while the
// level's vertices fit the table, hashed beyond, as nprt-net's encoding/hash_grid.rs.

const FEATURES: u32 = 19u;
const LEVELS: u32 = 8u;
const LEVEL_FEATURES: u32 = 2u;
const TABLE_SIZE: u32 = 8192u;

struct Corners {
    // Index of each vertex's first feature in the tables.
    row: array<u32, 8>,
    weight: array<f32, 8>,
}

fn grid_corners(position: vec3<f32>, level: u32, res: u32) -> Corners {
    let side = res + 1u;
    let dense = side * side * side <= TABLE_SIZE;
    var cell: vec3<u32>;
    var t: vec3<f32>;
    for (var a = 0u; a < 3u; a++) {
        let q = clamp((position[a] + 1.0) * 0.5, 0.0, 1.0) * f32(res);
        cell[a] = min(u32(floor(q)), res - 1u);
        t[a] = q - f32(cell[a]);
    }
    var c: Corners;
    for (var k = 0u; k < 8u; k++) {
        let bit = vec3<u32>(k & 1u, (k >> 1u) & 1u, (k >> 2u) & 1u);
        let v = cell + bit;
        var slot: u32;
        if (dense) {
            slot = v.x + side * (v.y + side * v.z);
        } else {
            slot = (v.x ^ (v.y * 2654435761u) ^ (v.z * 805459861u)) % TABLE_SIZE;
        }
        let s = select(vec3<f32>(1.0) - t, t, bit == vec3<u32>(1u));
        c.row[k] = (level * TABLE_SIZE + slot) * LEVEL_FEATURES;
        c.weight[k] = s.x * s.y * s.z;
    }
    return c;
}

fn row_position(r: u32) -> vec3<f32> {
    let f = r * FEATURES;
    return vec3<f32>(features[f], features[f + 1u], features[f + 2u]);
}
