// The hash grid's table gradient: each row's gradient at its encoding (the inputs after the
// `count` features it reads, in dx) sent back to the 8 vertices around its position at every
// level with their trilinear weights, as nprt-net's hash_grid::scatter (grid_corners). Rows share vertices,
// so the additions are atomic: a compare-and-swap loop on the value's bits (WGSL has no float
// atomics). Their order, and so the last bits of a sum, depends on scheduling.

struct GridBackward {
    rows: u32,
    count: u32,
    width: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> p: GridBackward;
@group(0) @binding(1) var<storage, read> features: array<f32>;
@group(0) @binding(2) var<storage, read> resolution: array<u32>;
@group(0) @binding(3) var<storage, read> dx: array<f32>;
@group(0) @binding(4) var<storage, read_write> d_table: array<atomic<u32>>;

fn add(i: u32, v: f32) {
    var old = atomicLoad(&d_table[i]);
    loop {
        let r = atomicCompareExchangeWeak(&d_table[i], old, bitcast<u32>(bitcast<f32>(old) + v));
        if (r.exchanged) {
            break;
        }
        old = r.old_value;
    }
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let r = id.x + id.y * groups.x * 64u;
    if (r >= p.rows) {
        return;
    }
    let o = r * p.width + p.count;
    let position = row_position(r);
    for (var level = 0u; level < LEVELS; level++) {
        let c = grid_corners(position, level, resolution[level]);
        let g = vec2<f32>(dx[o + level * LEVEL_FEATURES], dx[o + level * LEVEL_FEATURES + 1u]);
        for (var k = 0u; k < 8u; k++) {
            add(c.row[k], c.weight[k] * g.x);
            add(c.row[k] + 1u, c.weight[k] * g.y);
        }
    }
}
