// The training loss of each row and the gradient at its prediction. A row's prediction is its
// tracks' radiance as `combine` summed it, times the map's scale; its loss is the mean over the
// batch's values of loss_element's loss. `track_gradient` then takes the
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
    let e = array<vec2<f32>, 3>(
        loss_element(p.loss, q.x, ref_.x),
        loss_element(p.loss, q.y, ref_.y),
        loss_element(p.loss, q.z, ref_.z),
    );
    let value = vec3<f32>(e[0].x, e[1].x, e[2].x);
    let slope = vec3<f32>(e[0].y, e[1].y, e[2].y);
    row_loss[r] = value.x + value.y + value.z;
    let g = slope * p.norm * s;
    dr[3u * r] = g.x;
    dr[3u * r + 1u] = g.y;
    dr[3u * r + 2u] = g.z;
}
