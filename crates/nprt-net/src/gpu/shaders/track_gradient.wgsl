// One track's gradient at its shading outputs, from the gradient `dr` at its radiance (the
// same for every track: the prediction is their sum): each term's weight times its exp.

struct TrackGradient {
    rows: u32,
    // The track's kind's code (the kind table's index).
    kind: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> p: TrackGradient;
@group(0) @binding(1) var<storage, read> features: array<f32>;
@group(0) @binding(2) var<storage, read> out: array<f32>;
@group(0) @binding(3) var<storage, read> dr: array<f32>;
@group(0) @binding(4) var<storage, read_write> d_out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let r = id.x + id.y * groups.x * 64u;
    if (r >= p.rows) {
        return;
    }
    let e = exps(p.kind, r);
    let g = vec3<f32>(dr[3u * r], dr[3u * r + 1u], dr[3u * r + 2u]);
    let n = outputs(p.kind) * r;
    for (var t = 0u; t < KIND_TERMS[p.kind]; t++) {
        let d = g * term_weight(p.kind, t, r) * e[t];
        let i = n + 3u * t;
        d_out[i] = d.x;
        d_out[i + 1u] = d.y;
        d_out[i + 2u] = d.z;
    }
}
