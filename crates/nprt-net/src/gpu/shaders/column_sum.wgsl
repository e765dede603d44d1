// Sums of a matrix's columns over its rows, per row group: out[g · n + j] = Σ over rows i of
// group g of x[i · n + j] (one group when groups is 1: the bias gradient; one per view: the
// gradient at each view's light code). One thread per output value, adding its rows in order,
// so the sum does not depend on the device's scheduling.

struct ColumnSum {
    rows: u32,
    n: u32,
    groups: u32,
    accumulate: u32,
    // Where the sums start in out.
    out_off: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> p: ColumnSum;
@group(0) @binding(1) var<storage, read> x: array<f32>;
@group(0) @binding(2) var<storage, read> group_of: array<u32>;
@group(0) @binding(3) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let o = id.x + id.y * groups.x * 64u;
    if (o >= p.groups * p.n) {
        return;
    }
    let g = o / p.n;
    let j = o % p.n;
    var s = 0.0;
    for (var i = 0u; i < p.rows; i++) {
        if (p.groups == 1u || group_of[i] == g) {
            s += x[i * p.n + j];
        }
    }
    if (p.accumulate == 1u) {
        s += out[p.out_off + o];
    }
    out[p.out_off + o] = s;
}
