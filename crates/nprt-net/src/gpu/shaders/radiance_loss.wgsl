// The training loss of each row and the gradient at its prediction. A row's prediction is its
// tracks' radiance as `combine` summed it, times the map's scale; its loss is the mean over the
// batch's values of log-L1 (|log(1 + p) − log(1 + r)|) or relative L2 ((p − r)² / (p² + ε), p
// held constant in the weight), as nprt-net's Loss::element. `track_gradient` then takes the
// gradient to each track's outputs.

struct RadianceLoss {
    rows: u32,
    // 0: log-L1, 1: relative L2.
    loss: u32,
    _pad0: u32,
    _pad1: u32,
    // d mean / d value: 1 / (3 · rows of the whole batch), times the step's loss scale (1,
    // or a power of two in a mixed-precision step).
    norm: f32,
    _pad2: f32,
    _pad3: f32,
    _pad4: f32,
}

@group(0) @binding(0) var<uniform> p: RadianceLoss;
@group(0) @binding(1) var<storage, read> radiance: array<f32>;
@group(0) @binding(2) var<storage, read> reference: array<f32>;
@group(0) @binding(3) var<storage, read> scale: array<f32>;
@group(0) @binding(4) var<storage, read_write> dr: array<f32>;
@group(0) @binding(5) var<storage, read_write> row_loss: array<f32>;

const RELATIVE_L2_EPS: f32 = 0.01;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let r = id.x + id.y * groups.x * 64u;
    if (r >= p.rows) {
        return;
    }
    let c = vec3<f32>(radiance[3u * r], radiance[3u * r + 1u], radiance[3u * r + 2u]);
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
    let g = slope * p.norm * s;
    dr[3u * r] = g.x;
    dr[3u * r + 1u] = g.y;
    dr[3u * r + 2u] = g.z;
}
