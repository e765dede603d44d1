// A track's first-layer inputs for each row: the pixel features it reads (19 per row in, in
// the order of `index`) and, for a track with a hash grid, the grid's encoding of the position
// after them: at each level the trilinear interpolation of the 8 vertices around the position,
// indexed directly while the level's vertices fit the table, hashed beyond (as
// nprt-net's encoding/hash_grid.rs, which the CPU engine and training use).

struct Inputs {
    rows: u32,
    count: u32,
    width: u32,
    grid: u32,
}

@group(0) @binding(0) var<uniform> p: Inputs;
@group(0) @binding(1) var<storage, read> features: array<f32>;
@group(0) @binding(2) var<storage, read> index: array<u32>;
@group(0) @binding(3) var<storage, read> table: array<f32>;
@group(0) @binding(4) var<storage, read> resolution: array<u32>;
@group(0) @binding(5) var<storage, read_write> x: array<f32>;

const FEATURES: u32 = 19u;
const LEVELS: u32 = 8u;
const LEVEL_FEATURES: u32 = 2u;
const TABLE_SIZE: u32 = 8192u;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let r = id.x + id.y * groups.x * 64u;
    if (r >= p.rows) {
        return;
    }
    let f = r * FEATURES;
    let o = r * p.width;
    for (var i = 0u; i < p.count; i++) {
        x[o + i] = features[f + index[i]];
    }
    if (p.grid == 0u) {
        return;
    }
    let position = vec3<f32>(features[f], features[f + 1u], features[f + 2u]);
    for (var level = 0u; level < LEVELS; level++) {
        let res = resolution[level];
        let side = res + 1u;
        let dense = side * side * side <= TABLE_SIZE;
        var cell: vec3<u32>;
        var t: vec3<f32>;
        for (var a = 0u; a < 3u; a++) {
            let q = clamp((position[a] + 1.0) * 0.5, 0.0, 1.0) * f32(res);
            cell[a] = min(u32(floor(q)), res - 1u);
            t[a] = q - f32(cell[a]);
        }
        var value = vec2<f32>(0.0, 0.0);
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
            let weight = s.x * s.y * s.z;
            let row = (level * TABLE_SIZE + slot) * LEVEL_FEATURES;
            value += weight * vec2<f32>(table[row], table[row + 1u]);
        }
        x[o + p.count + level * LEVEL_FEATURES] = value.x;
        x[o + p.count + level * LEVEL_FEATURES + 1u] = value.y;
    }
}
