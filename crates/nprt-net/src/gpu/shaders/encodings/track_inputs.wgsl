// A track's first-layer inputs for each row: the pixel features it reads (19 per row in, in
// the order of `index`) and, for a track with a hash grid, the grid's encoding of the position
// after them: at each level the trilinear interpolation of the 8 vertices around the position
// (grid_corners).

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
    let position = row_position(r);
    for (var level = 0u; level < LEVELS; level++) {
        let c = grid_corners(position, level, resolution[level]);
        var value = vec2<f32>(0.0, 0.0);
        for (var k = 0u; k < 8u; k++) {
            value += c.weight[k] * vec2<f32>(table[c.row[k]], table[c.row[k] + 1u]);
        }
        x[o + p.count + level * LEVEL_FEATURES] = value.x;
        x[o + p.count + level * LEVEL_FEATURES + 1u] = value.y;
    }
}
