// The convolution's share of the gradient at a light-encoder block's input, added to the
// skip's (encoder_pool_backward): per input value (view, ci, y, x) the sum over channels c and
// taps of dz[c] at the output pixel whose tap read it, times that tap's weight.

struct InputBackward {
    c_in: u32,
    h: u32,
    w: u32,
    views: u32,
    // Where the block's weight starts in params.
    weight_off: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> p: InputBackward;
@group(0) @binding(1) var<storage, read> params: array<f32>;
@group(0) @binding(2) var<storage, read> dz: array<f32>;
@group(0) @binding(3) var<storage, read_write> d_input: array<f32>;

const CHANNELS: u32 = 32u;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    let hw = p.h * p.w;
    if (i >= p.views * p.c_in * hw) {
        return;
    }
    let view = i / (p.c_in * hw);
    let ci = (i / hw) % p.c_in;
    let y = i32((i / p.w) % p.h);
    let x = i32(i % p.w);
    var s = 0.0;
    for (var c = 0u; c < CHANNELS; c++) {
        let d = (view * CHANNELS + c) * hw;
        let wb = p.weight_off + (c * p.c_in + ci) * 9u;
        for (var ky = 0; ky < 3; ky++) {
            // The output pixel whose tap ky read row y.
            let oy = y - ky + 1;
            if (oy < 0 || oy >= i32(p.h)) {
                continue;
            }
            for (var kx = 0; kx < 3; kx++) {
                let ox = x - kx + 1;
                if (ox < 0 || ox >= i32(p.w)) {
                    continue;
                }
                s += dz[d + u32(oy) * p.w + u32(ox)] * params[wb + u32(ky * 3 + kx)];
            }
        }
    }
    d_input[i] += s;
}
