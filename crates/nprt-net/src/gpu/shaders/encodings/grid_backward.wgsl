// The hash grid's table gradient: each row's gradient at its encoding (the inputs after the
// `count` features it reads, in dx) sent back to the 8 vertices around its position at every
// level with their trilinear weights (grid_corners), as nprt-net's hash_grid::scatter.
//
// Rows share vertices, and float atomics would add in the device's order, so that no two runs
// gave the same bits and a resumed run could not equal an uninterrupted one. Instead each
// thread owns SLOTS consecutive slots of one level's table for one chunk of `chunk` rows, and
// adds, row by row in order, what those rows send there, into the chunk's own copy of the
// tables (partial, chunk c's at c · LEVELS · TABLE_SIZE · LEVEL_FEATURES); column_sum then adds
// the chunks' copies in order. A fixed order throughout, and chunks × 1,024 threads.

struct GridBackward {
    rows: u32,
    count: u32,
    width: u32,
    chunk: u32,
}

@group(0) @binding(0) var<uniform> p: GridBackward;
@group(0) @binding(1) var<storage, read> features: array<f32>;
@group(0) @binding(2) var<storage, read> resolution: array<u32>;
@group(0) @binding(3) var<storage, read> dx: array<f32>;
@group(0) @binding(4) var<storage, read_write> partial: array<f32>;

// Slots a thread owns: 8192 / 64 = 128 threads per level and chunk.
const SLOTS: u32 = 64u;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    let per_chunk = LEVELS * TABLE_SIZE / SLOTS;
    let chunks = (p.rows + p.chunk - 1u) / p.chunk;
    if (i >= chunks * per_chunk) {
        return;
    }
    let c = i / per_chunk;
    let level = (i % per_chunk) / (TABLE_SIZE / SLOTS);
    let first = (level * TABLE_SIZE + (i % (TABLE_SIZE / SLOTS)) * SLOTS) * LEVEL_FEATURES;
    let end = first + SLOTS * LEVEL_FEATURES;
    let base = c * LEVELS * TABLE_SIZE * LEVEL_FEATURES;
    for (var k = first; k < end; k++) {
        partial[base + k] = 0.0;
    }
    let res = resolution[level];
    for (var r = c * p.chunk; r < min(p.rows, (c + 1u) * p.chunk); r++) {
        let corners = grid_corners(row_position(r), level, res);
        let o = r * p.width + p.count + level * LEVEL_FEATURES;
        for (var k = 0u; k < 8u; k++) {
            let row = corners.row[k];
            if (row >= first && row < end) {
                partial[base + row] += corners.weight[k] * dx[o];
                partial[base + row + 1u] += corners.weight[k] * dx[o + 1u];
            }
        }
    }
}
