// A k × k convolution (zero padding, stride 1) over `views` images, with ReLU after when
// relu = 1: input views × c_in × h × w, output views × c_out × h × w, channel-major as the CPU
// engine holds them (weight c_out × c_in × k × k). One thread per output value. The Deep
// Shading U-Net's layers; the light encoder's blocks fuse theirs (encoder_block).

struct Conv {
    c_in: u32,
    c_out: u32,
    h: u32,
    w: u32,
    views: u32,
    k: u32,
    relu: u32,
    _pad0: u32,
}

@group(0) @binding(0) var<uniform> p: Conv;
@group(0) @binding(1) var<storage, read> input: array<f32>;
@group(0) @binding(2) var<storage, read> weight: array<f32>;
@group(0) @binding(3) var<storage, read> bias: array<f32>;
@group(0) @binding(4) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    let hw = p.h * p.w;
    if (i >= p.views * p.c_out * hw) {
        return;
    }
    let view = i / (p.c_out * hw);
    let c = (i / hw) % p.c_out;
    let y = i32((i / p.w) % p.h);
    let x = i32(i % p.w);
    let r = i32(p.k / 2u);
    let taps = p.k * p.k;
    var s = 0.0;
    for (var ci = 0u; ci < p.c_in; ci++) {
        let src = (view * p.c_in + ci) * hw;
        let wb = (c * p.c_in + ci) * taps;
        for (var ky = 0; ky < i32(p.k); ky++) {
            let yy = y + ky - r;
            if (yy < 0 || yy >= i32(p.h)) {
                continue;
            }
            for (var kx = 0; kx < i32(p.k); kx++) {
                let xx = x + kx - r;
                if (xx < 0 || xx >= i32(p.w)) {
                    continue;
                }
                s += weight[wb + u32(ky) * p.k + u32(kx)] * input[src + u32(yy) * p.w + u32(xx)];
            }
        }
    }
    let z = s + bias[c];
    out[i] = select(z, max(z, 0.0), p.relu == 1u);
}
