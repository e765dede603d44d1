// One block of the light encoder over `views` maps: 3×3 convolution to 32 channels with zero
// padding, ReLU, the block's input added (zero beyond its channels), 2×2 max-pool (the first of
// a window's maxima in row order). Input views × c_in × h × w, output views × 32 × h/2 × w/2,
// channel-major as the CPU engine holds them; four threads per output value (dispatch 4 × the
// outputs). With keep = 1 (training) it also writes, per output value, which of its window's
// four values it took (bits 0-1) and whether that value's convolution passed the ReLU (bit 2):
// what backward needs.

struct Block {
    c_in: u32,
    h: u32,
    w: u32,
    views: u32,
    keep: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> p: Block;
@group(0) @binding(1) var<storage, read> input: array<f32>;
@group(0) @binding(2) var<storage, read> weight: array<f32>;
@group(0) @binding(3) var<storage, read> bias: array<f32>;
@group(0) @binding(4) var<storage, read_write> out: array<f32>;
@group(0) @binding(5) var<storage, read_write> tape: array<u32>;

const CHANNELS: u32 = 32u;

fn conv(base: u32, c: u32, y: u32, x: u32) -> f32 {
    var s = 0.0;
    for (var ci = 0u; ci < p.c_in; ci++) {
        for (var ky = 0u; ky < 3u; ky++) {
            let yy = i32(y + ky) - 1;
            if (yy < 0 || yy >= i32(p.h)) {
                continue;
            }
            for (var kx = 0u; kx < 3u; kx++) {
                let xx = i32(x + kx) - 1;
                if (xx < 0 || xx >= i32(p.w)) {
                    continue;
                }
                s += weight[((c * p.c_in + ci) * 3u + ky) * 3u + kx]
                    * input[base + (ci * p.h + u32(yy)) * p.w + u32(xx)];
            }
        }
    }
    return s + bias[c];
}

// A window's four convolutions, one per thread, met in workgroup memory: one thread per output
// value walked all four in turn, and the last blocks (a few hundred outputs of 288
// multiply-adds each) were chains of dependent loads that left the GPU idle.
var<workgroup> conv_of: array<f32, 64>;
var<workgroup> value_of: array<f32, 64>;

// Four threads per output value (the window's slots in row order), so a workgroup covers 16.
@compute @workgroup_size(64)
fn main(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) t: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let ho = p.h / 2u;
    let wo = p.w / 2u;
    // Rows of workgroups past the 65,535 one dimension allows.
    let thread = id.x + id.y * groups.x * 64u;
    let i = thread / 4u;
    let d = thread % 4u;
    let live = i < p.views * CHANNELS * ho * wo;
    var z = 0.0;
    var v = -3.0e38;
    if (live) {
        let view = i / (CHANNELS * ho * wo);
        let c = (i / (ho * wo)) % CHANNELS;
        let oy = (i / wo) % ho;
        let ox = i % wo;
        let base = view * p.c_in * p.h * p.w;
        let y = 2u * oy + d / 2u;
        let x = 2u * ox + d % 2u;
        z = conv(base, c, y, x);
        v = max(z, 0.0);
        if (c < p.c_in) {
            v += input[base + (c * p.h + y) * p.w + x];
        }
    }
    conv_of[t] = z;
    value_of[t] = v;
    workgroupBarrier();
    if (!live || d != 0u) {
        return;
    }
    var m = -3.0e38;
    var taken = 0u;
    for (var k = 0u; k < 4u; k++) {
        if (value_of[t + k] > m) {
            m = value_of[t + k];
            taken = k | select(0u, 4u, conv_of[t + k] > 0.0);
        }
    }
    out[i] = m;
    if (p.keep == 1u) {
        tape[i] = taken;
    }
}
