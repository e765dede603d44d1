// The convolution's share of the gradient at a light-encoder block's input, added to the
// skip's (encoder_pool_backward): per input value (view, ci, y, x) the sum over channels c and
// taps of dz[c] at the output pixel whose tap read it, times that tap's weight. Four threads
// per input value (dispatch 4 × the values).

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
// Threads per input value, each over a quarter of the channels in order, their sums added in
// workgroup memory in the same order: one thread over all 32 channels' 288 taps made the last
// blocks (a few thousand values) chains of dependent loads on an idle GPU.
const PARTS: u32 = 4u;

var<workgroup> part_of: array<f32, 64>;

@compute @workgroup_size(64)
fn main(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) t: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let thread = id.x + id.y * groups.x * 64u;
    let i = thread / PARTS;
    let part = thread % PARTS;
    let hw = p.h * p.w;
    let live = i < p.views * p.c_in * hw;
    var s = 0.0;
    if (live) {
        let view = i / (p.c_in * hw);
        let ci = (i / hw) % p.c_in;
        let y = i32((i / p.w) % p.h);
        let x = i32(i % p.w);
        let per_part = CHANNELS / PARTS;
        for (var c = part * per_part; c < (part + 1u) * per_part; c++) {
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
    }
    part_of[t] = s;
    workgroupBarrier();
    if (!live || part != 0u) {
        return;
    }
    d_input[i] += ((part_of[t] + part_of[t + 1u]) + part_of[t + 2u]) + part_of[t + 3u];
}
