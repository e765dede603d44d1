// One track's gradient at its shading outputs, from the gradient `dr` at its radiance (the
// same for every track: the prediction is their sum): each term's weight times dr times the
// term's slope in the output, its exp, or for a linear track the light code's value. A linear
// track's gradient at its row's light code, Σ_t dr · weight_t · its coefficients, is written
// per row into `d_code` (code_gradient 1) for a per-view sum. Trained on transfer vectors
// (`transfer` 1), `dr` holds the gradient at each row's vector (rows × 3K, transfer_loss's) and
// coefficient j of term t takes its value times the term's weight; the code has no gradient.

struct TrackGradient {
    rows: u32,
    // The track's kind's code (the kind table's index).
    kind: u32,
    // K for a linear track, 0 otherwise (combine's).
    coefficients: u32,
    // Values between one view's code and the next in `light` (combine's).
    code_stride: u32,
    // 1: write each row's gradient at its light code into `d_code` (rows × 3K).
    code_gradient: u32,
    // 1: `dr` is the gradient at the rows' transfer vectors.
    transfer: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> p: TrackGradient;
@group(0) @binding(1) var<storage, read> features: array<f32>;
@group(0) @binding(2) var<storage, read> out: array<f32>;
@group(0) @binding(3) var<storage, read> light: array<f32>;
@group(0) @binding(4) var<storage, read> views: array<u32>;
@group(0) @binding(5) var<storage, read> dr: array<f32>;
@group(0) @binding(6) var<storage, read_write> d_out: array<f32>;
@group(0) @binding(7) var<storage, read_write> d_code: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let r = id.x + id.y * groups.x * 64u;
    if (r >= p.rows) {
        return;
    }
    let k = p.coefficients;
    let n = outputs(p.kind, k) * r;
    if (p.transfer == 1u) {
        for (var j = 0u; j < k; j++) {
            let o = 3u * (r * k + j);
            let g = vec3<f32>(dr[o], dr[o + 1u], dr[o + 2u]);
            for (var t = 0u; t < KIND_TERMS[p.kind]; t++) {
                let d = g * term_weight(p.kind, t, r);
                let i = n + 3u * (t * k + j);
                d_out[i] = d.x;
                d_out[i + 1u] = d.y;
                d_out[i + 2u] = d.z;
            }
        }
        return;
    }
    let g = vec3<f32>(dr[3u * r], dr[3u * r + 1u], dr[3u * r + 2u]);
    if (k == 0u) {
        let e = terms(p.kind, r, 0u, 0u);
        for (var t = 0u; t < KIND_TERMS[p.kind]; t++) {
            let d = g * term_weight(p.kind, t, r) * e[t];
            let i = n + 3u * t;
            d_out[i] = d.x;
            d_out[i + 1u] = d.y;
            d_out[i + 2u] = d.z;
        }
        return;
    }
    let code = code_at(r, p.code_stride);
    for (var j = 0u; j < k; j++) {
        let e = code_value(code, j);
        var dc = vec3<f32>(0.0);
        for (var t = 0u; t < KIND_TERMS[p.kind]; t++) {
            let dt = g * term_weight(p.kind, t, r);
            let i = n + 3u * (t * k + j);
            let d = dt * e;
            d_out[i] = d.x;
            d_out[i + 1u] = d.y;
            d_out[i + 2u] = d.z;
            dc += dt * vec3<f32>(out[i], out[i + 1u], out[i + 2u]);
        }
        if (p.code_gradient == 1u) {
            let o = 3u * (r * k + j);
            d_code[o] = dc.x;
            d_code[o + 1u] = dc.y;
            d_code[o + 2u] = dc.z;
        }
    }
}
