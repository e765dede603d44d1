// Training on transfer vectors (cpu::transport's transfer_block), one track per dispatch: the
// design's vector per row, T̂_j = Σ_tracks transfer_value(j) (track_radiance), written by the
// first track into `sum` or added by the next; the last compares it with the recorded vector:
// the squared error of each of the row's 3K values, counted 1/K (so that the loss read back,
// divided by 3 · rows, is their mean), and its gradient, 2 · error · norm, into `d_transfer`
// for track_gradient.

struct TransferLoss {
    rows: u32,
    // The track's kind's code (the kind table's index).
    kind: u32,
    // K, the coefficients per channel.
    coefficients: u32,
    // 1: add to `sum`; 0: this is the first track.
    accumulate: u32,
    // 1: the last track: make the loss and its gradient.
    last: u32,
    _pad0: u32,
    _pad1: u32,
    // d mean / d value: 1 / (3K · rows), times the step's loss scale.
    norm: f32,
}

@group(0) @binding(0) var<uniform> p: TransferLoss;
@group(0) @binding(1) var<storage, read> features: array<f32>;
@group(0) @binding(2) var<storage, read> out: array<f32>;
@group(0) @binding(3) var<storage, read> target_: array<f32>;
@group(0) @binding(4) var<storage, read_write> sum: array<f32>;
@group(0) @binding(5) var<storage, read_write> d_transfer: array<f32>;
@group(0) @binding(6) var<storage, read_write> row_loss: array<f32>;
// track_radiance's light codes, which a transfer vector does not read: placeholders for the
// names its shared functions use.
var<private> light: array<f32, 1>;
var<private> views: array<u32, 1>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let r = id.x + id.y * groups.x * 64u;
    if (r >= p.rows) {
        return;
    }
    let k = p.coefficients;
    var loss = 0.0;
    for (var j = 0u; j < k; j++) {
        var v = transfer_value(p.kind, r, k, j);
        let o = 3u * (r * k + j);
        if (p.accumulate == 1u) {
            v += vec3<f32>(sum[o], sum[o + 1u], sum[o + 2u]);
        }
        if (p.last == 0u) {
            sum[o] = v.x;
            sum[o + 1u] = v.y;
            sum[o + 2u] = v.z;
            continue;
        }
        let e = v - vec3<f32>(target_[o], target_[o + 1u], target_[o + 2u]);
        loss += dot(e, e);
        let d = 2.0 * e * p.norm;
        d_transfer[o] = d.x;
        d_transfer[o + 1u] = d.y;
        d_transfer[o + 2u] = d.z;
    }
    if (p.last == 1u) {
        row_loss[r] = loss / f32(k);
    }
}
