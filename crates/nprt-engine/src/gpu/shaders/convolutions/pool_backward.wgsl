// Backward through one U-Net encoder level's pool and its skip: per value of the level's last
// convolution (views × c × h × w), the gradient of the pooled value that took it (zero where
// none did) plus its skip's, which sits in the decoder's concatenated input gradient after the
// up-sampled `c_up` channels (d_cat: views × (c_up + c) × h × w); passed on where the
// convolution's ReLU output `act` is positive: the gradient at its pre-activation.

struct PoolBackward {
    c: u32,
    h: u32,
    w: u32,
    views: u32,
    c_up: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> p: PoolBackward;
@group(0) @binding(1) var<storage, read> taken: array<u32>;
@group(0) @binding(2) var<storage, read> d_pooled: array<f32>;
@group(0) @binding(3) var<storage, read> d_cat: array<f32>;
@group(0) @binding(4) var<storage, read> act: array<f32>;
@group(0) @binding(5) var<storage, read_write> dz: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    let hw = p.h * p.w;
    if (i >= p.views * p.c * hw) {
        return;
    }
    let plane = i / hw;
    let view = plane / p.c;
    let c = plane % p.c;
    let y = (i / p.w) % p.h;
    let x = i % p.w;
    let ho = p.h / 2u;
    let wo = p.w / 2u;
    var d = 0.0;
    let o = (plane * ho + y / 2u) * wo + x / 2u;
    if (taken[o] == (y % 2u) * 2u + x % 2u) {
        d = d_pooled[o];
    }
    d += d_cat[(view * (p.c_up + p.c) + p.c_up + c) * hw + y * p.w + x];
    dz[i] = select(0.0, d, act[i] > 0.0);
}
