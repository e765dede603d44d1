// The hash grid's table gradient: each row's gradient at its encoding (the inputs after the
// `count` features it reads, in dx) sent back to the 8 vertices around its position at every
// level with their trilinear weights (grid_corners), as nprt-net's hash_grid::scatter.
//
// Rows share vertices, and float atomics would add in the device's order, so that no two runs
// gave the same bits and a resumed run could not equal an uninterrupted one. Instead each
// thread owns SLOTS consecutive slots of one level's table and adds, row by row in order,
// what lands there: a fixed order, no atomics, at the price of every thread visiting every
// row.

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
@group(0) @binding(4) var<storage, read_write> d_table: array<f32>;

// Slots a thread owns: 8192 / 64 = 128 threads per level.
const SLOTS: u32 = 64u;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    if (i >= LEVELS * TABLE_SIZE / SLOTS) {
        return;
    }
    let level = i / (TABLE_SIZE / SLOTS);
    let first = (level * TABLE_SIZE + (i % (TABLE_SIZE / SLOTS)) * SLOTS) * LEVEL_FEATURES;
    let end = first + SLOTS * LEVEL_FEATURES;
    let res = resolution[level];
    for (var r = 0u; r < p.rows; r++) {
        let c = grid_corners(row_position(r), level, res);
        let o = r * p.width + p.count + level * LEVEL_FEATURES;
        for (var k = 0u; k < 8u; k++) {
            let row = c.row[k];
            if (row >= first && row < end) {
                d_table[row] += c.weight[k] * dx[o];
                d_table[row + 1u] += c.weight[k] * dx[o + 1u];
            }
        }
    }
}
