// Backward through a light-encoder block's pool and ReLU: per value of the block's
// convolution (views × 32 × h × w), the gradient of the pooled output that took it (zero where
// none did), passed on as dz where the convolution passed the ReLU, and, for the block's
// first c_in channels with grad_input = 1, as the skip's share of the gradient at the block's
// input (which encoder_input_backward then adds the convolution's share to).

struct PoolBackward {
    c_in: u32,
    h: u32,
    w: u32,
    views: u32,
    grad_input: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> p: PoolBackward;
@group(0) @binding(1) var<storage, read> tape: array<u32>;
@group(0) @binding(2) var<storage, read> d_pooled: array<f32>;
@group(0) @binding(3) var<storage, read_write> dz: array<f32>;
@group(0) @binding(4) var<storage, read_write> d_input: array<f32>;

const CHANNELS: u32 = 32u;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    let hw = p.h * p.w;
    if (i >= p.views * CHANNELS * hw) {
        return;
    }
    let view = i / (CHANNELS * hw);
    let c = (i / hw) % CHANNELS;
    let y = (i / p.w) % p.h;
    let x = i % p.w;
    let ho = p.h / 2u;
    let wo = p.w / 2u;
    var d = 0.0;
    var relu = false;
    if (y / 2u < ho && x / 2u < wo) {
        let o = ((view * CHANNELS + c) * ho + y / 2u) * wo + x / 2u;
        let taken = tape[o];
        if ((taken & 3u) == (y % 2u) * 2u + x % 2u) {
            d = d_pooled[o];
            relu = (taken & 4u) != 0u;
        }
    }
    dz[i] = select(0.0, d, relu);
    if (p.grad_input == 1u && c < p.c_in) {
        d_input[((view * p.c_in + c) * p.h + y) * p.w + x] = d;
    }
}
