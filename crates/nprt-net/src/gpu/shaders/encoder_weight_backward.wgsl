// The gradients of a light-encoder block's convolution: per weight (c, ci, ky, kx) the sum over
// views and pixels of dz[c] times the input tap it multiplied, and per channel c the sum of
// dz[c] (its bias). One thread per value, adding in a fixed order.

struct WeightBackward {
    c_in: u32,
    h: u32,
    w: u32,
    views: u32,
    // Where the weight's and the bias's gradients start in grads.
    weight_off: u32,
    bias_off: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> p: WeightBackward;
@group(0) @binding(1) var<storage, read> input: array<f32>;
@group(0) @binding(2) var<storage, read> dz: array<f32>;
@group(0) @binding(3) var<storage, read_write> grads: array<f32>;

const CHANNELS: u32 = 32u;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    let taps = p.c_in * 9u;
    if (i >= CHANNELS * (taps + 1u)) {
        return;
    }
    let c = i / (taps + 1u);
    let j = i % (taps + 1u);
    let hw = p.h * p.w;
    var s = 0.0;
    if (j == taps) {
        for (var view = 0u; view < p.views; view++) {
            let d = (view * CHANNELS + c) * hw;
            for (var k = 0u; k < hw; k++) {
                s += dz[d + k];
            }
        }
        grads[p.bias_off + c] = s;
        return;
    }
    let ci = j / 9u;
    let ky = i32(j % 9u / 3u) - 1;
    let kx = i32(j % 3u) - 1;
    for (var view = 0u; view < p.views; view++) {
        let d = (view * CHANNELS + c) * hw;
        let src = (view * p.c_in + ci) * hw;
        for (var y = 0u; y < p.h; y++) {
            let sy = i32(y) + ky;
            if (sy < 0 || sy >= i32(p.h)) {
                continue;
            }
            for (var x = 0u; x < p.w; x++) {
                let sx = i32(x) + kx;
                if (sx < 0 || sx >= i32(p.w)) {
                    continue;
                }
                s += dz[d + y * p.w + x] * input[src + u32(sy) * p.w + u32(sx)];
            }
        }
    }
    grads[p.weight_off + c * taps + j] = s;
}
