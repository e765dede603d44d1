// The gradient at a k × k convolution's input (views × c_in × h × w) from the gradient dz at
// its output (views × c_out × h × w): per input value the sum over output channels and taps of
// dz at the output pixel whose tap read it, times that tap's weight. With `mask` = 1 it passes
// only where `act` (the input, a ReLU's output) is positive: the gradient at that ReLU's input;
// with `add` = 1 it is added to what d_input holds (the light encoder's skip share). Four
// threads per input value (dispatch 4 × the values), each over a quarter of the channels in
// order, their sums added in workgroup memory in the same order: one thread over all channels'
// taps made the light encoder's last blocks (a few thousand values) chains of dependent loads
// on an idle GPU.

struct InputBackward {
    c_in: u32,
    c_out: u32,
    h: u32,
    w: u32,
    views: u32,
    k: u32,
    add: u32,
    mask: u32,
}

@group(0) @binding(0) var<uniform> p: InputBackward;
@group(0) @binding(1) var<storage, read> weight: array<f32>;
@group(0) @binding(2) var<storage, read> dz: array<f32>;
@group(0) @binding(3) var<storage, read> act: array<f32>;
@group(0) @binding(4) var<storage, read_write> d_input: array<f32>;

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
    let r = i32(p.k / 2u);
    let taps = p.k * p.k;
    var s = 0.0;
    if (live) {
        let view = i / (p.c_in * hw);
        let ci = (i / hw) % p.c_in;
        let y = i32((i / p.w) % p.h);
        let x = i32(i % p.w);
        for (var c = part * p.c_out / PARTS; c < (part + 1u) * p.c_out / PARTS; c++) {
            let d = (view * p.c_out + c) * hw;
            let wb = (c * p.c_in + ci) * taps;
            for (var ky = 0; ky < i32(p.k); ky++) {
                // The output pixel whose tap ky read row y.
                let oy = y - ky + r;
                if (oy < 0 || oy >= i32(p.h)) {
                    continue;
                }
                for (var kx = 0; kx < i32(p.k); kx++) {
                    let ox = x - kx + r;
                    if (ox < 0 || ox >= i32(p.w)) {
                        continue;
                    }
                    s += dz[d + u32(oy) * p.w + u32(ox)] * weight[wb + u32(ky) * p.k + u32(kx)];
                }
            }
        }
    }
    part_of[t] = s;
    workgroupBarrier();
    if (!live || part != 0u) {
        return;
    }
    var v = ((part_of[t] + part_of[t + 1u]) + part_of[t + 2u]) + part_of[t + 3u];
    if (p.mask == 1u && !(act[i] > 0.0)) {
        v = 0.0;
    }
    if (p.add == 1u) {
        d_input[i] += v;
    } else {
        d_input[i] = v;
    }
}
