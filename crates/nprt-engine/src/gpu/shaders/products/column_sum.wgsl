// Sums of a matrix's columns over its rows, per row group: out[g · n + j] = Σ over rows i of
// group g of x[i · n + j] (one group when groups is 1: the bias gradient; one per view: the
// gradient at each view's light code). With chunk > 0 the rows are cut into chunks of that
// many and each chunk's sums go to their own block of out (chunk c's at c · groups · n), which
// a second pass sums over the chunks: a GPU then has chunks × groups × n threads to run
// instead of groups × n. Each thread adds its rows in order, so no sum depends on the device's
// scheduling.

struct ColumnSum {
    rows: u32,
    n: u32,
    groups: u32,
    accumulate: u32,
    // Where the sums start in out.
    out_off: u32,
    // Rows per chunk; 0: all rows in one.
    chunk: u32,
    // Sums from index tail_at on go to tail_out from tail_off instead (0: none): a weight's
    // gradient summed over chunks with its bias's on an extra row, each to its own place, or
    // an MLP's with its first layer's sums per view.
    tail_at: u32,
    tail_off: u32,
}

@group(0) @binding(0) var<uniform> p: ColumnSum;
@group(0) @binding(1) var<storage, read> x: array<f32>;
@group(0) @binding(2) var<storage, read> group_of: array<u32>;
@group(0) @binding(3) var<storage, read_write> out: array<f32>;
@group(0) @binding(4) var<storage, read_write> tail_out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let o = id.x + id.y * groups.x * 64u;
    let per_chunk = select(p.rows, p.chunk, p.chunk > 0u);
    let chunks = (p.rows + per_chunk - 1u) / per_chunk;
    if (o >= max(chunks, 1u) * p.groups * p.n) {
        return;
    }
    let c = o / (p.groups * p.n);
    let g = (o / p.n) % p.groups;
    let j = o % p.n;
    var s = 0.0;
    for (var i = c * per_chunk; i < min(p.rows, (c + 1u) * per_chunk); i++) {
        if (p.groups == 1u || group_of[i] == g) {
            s += x[i * p.n + j];
        }
    }
    if (p.tail_at > 0u && o >= p.tail_at) {
        let at = p.tail_off + (o - p.tail_at);
        if (p.accumulate == 1u) {
            s += tail_out[at];
        }
        tail_out[at] = s;
        return;
    }
    let at = p.out_off + o;
    if (p.accumulate == 1u) {
        s += out[at];
    }
    out[at] = s;
}
