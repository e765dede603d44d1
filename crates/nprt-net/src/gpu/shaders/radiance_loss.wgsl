// The training loss of each row and the gradient at its tracks' shading outputs. A row's
// prediction is what the frame path's combine makes (track_radiance summed over tracks, times
// the map's scale); its loss is the mean
// over the batch's values of log-L1 (|log(1 + p) − log(1 + r)|) or relative L2
// ((p − r)² / (p² + ε), p held constant in the weight), as nprt-net's Loss::element.

struct RadianceLoss {
    rows: u32,
    tracks: u32,
    // Per track: its kind's code (the kind table's index).
    kind0: u32,
    kind1: u32,
    // 0: log-L1, 1: relative L2.
    loss: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    // d mean / d value: 1 / (3 · rows of the whole batch), times the step's loss scale (1,
    // or a power of two in a mixed-precision step).
    norm: f32,
    _pad3: f32,
    _pad4: f32,
    _pad5: f32,
}

@group(0) @binding(0) var<uniform> p: RadianceLoss;
@group(0) @binding(1) var<storage, read> features: array<f32>;
@group(0) @binding(2) var<storage, read> reference: array<f32>;
@group(0) @binding(3) var<storage, read> scale: array<f32>;
@group(0) @binding(4) var<storage, read> out0: array<f32>;
@group(0) @binding(5) var<storage, read> out1: array<f32>;
@group(0) @binding(6) var<storage, read_write> d_out0: array<f32>;
@group(0) @binding(7) var<storage, read_write> d_out1: array<f32>;
@group(0) @binding(8) var<storage, read_write> row_loss: array<f32>;

const RELATIVE_L2_EPS: f32 = 0.01;

// The gradient at a track's outputs from the gradient dr at its radiance.
fn store_gradient(kind: u32, out: u32, r: u32, e: array<vec3<f32>, MAX_TERMS>, dr: vec3<f32>) {
    let n = outputs(kind) * r;
    for (var t = 0u; t < KIND_TERMS[kind]; t++) {
        let d = dr * term_weight(kind, t, r) * e[t];
        let i = n + 3u * t;
        if (out == 0u) {
            d_out0[i] = d.x;
            d_out0[i + 1u] = d.y;
            d_out0[i + 2u] = d.z;
        } else {
            d_out1[i] = d.x;
            d_out1[i + 1u] = d.y;
            d_out1[i + 2u] = d.z;
        }
    }
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let r = id.x + id.y * groups.x * 64u;
    if (r >= p.rows) {
        return;
    }
    let e0 = exps(p.kind0, 0u, r);
    var e1: array<vec3<f32>, MAX_TERMS>;
    var c = track_radiance(p.kind0, r, e0);
    if (p.tracks == 2u) {
        e1 = exps(p.kind1, 1u, r);
        c += track_radiance(p.kind1, r, e1);
    }
    let s = vec3<f32>(scale[3u * r], scale[3u * r + 1u], scale[3u * r + 2u]);
    let ref_ = vec3<f32>(reference[3u * r], reference[3u * r + 1u], reference[3u * r + 2u]);
    let q = c * s;
    var value: vec3<f32>;
    var slope: vec3<f32>;
    if (p.loss == 0u) {
        let d = log(1.0 + q) - log(1.0 + ref_);
        value = abs(d);
        slope = sign(d) / (1.0 + q);
    } else {
        let d = q - ref_;
        let w = 1.0 / (q * q + RELATIVE_L2_EPS);
        value = d * d * w;
        slope = 2.0 * d * w;
    }
    row_loss[r] = value.x + value.y + value.z;
    let dr = slope * p.norm * s;
    store_gradient(p.kind0, 0u, r, e0, dr);
    if (p.tracks == 2u) {
        store_gradient(p.kind1, 1u, r, e1, dr);
    }
}
