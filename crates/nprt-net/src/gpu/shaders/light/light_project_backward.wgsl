// The gradient of a learned basis' functions from the gradient at the batch's light codes
// (cpu::light_model's LightBasis::backward): function j at texel t gets its solid angle times
// Σ over views and channels of d_code[v, j·3 + c] · input[v, c, t]; one thread a value, the
// views and channels added in order.

struct LightProjectBackward {
    size: u32,
    texels: u32,
    views: u32,
    _pad0: u32,
}

@group(0) @binding(0) var<uniform> p: LightProjectBackward;
@group(0) @binding(1) var<storage, read> solid: array<f32>;
@group(0) @binding(2) var<storage, read> pixels: array<f32>;
@group(0) @binding(3) var<storage, read> d_code: array<f32>;
// K × texels.
@group(0) @binding(4) var<storage, read_write> d_functions: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Values of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    if (i >= p.size * p.texels) {
        return;
    }
    let j = i / p.texels;
    let t = i % p.texels;
    var sum = 0.0;
    for (var v = 0u; v < p.views; v++) {
        for (var c = 0u; c < 3u; c++) {
            sum += d_code[v * 3u * p.size + 3u * j + c] * pixels[(3u * v + c) * p.texels + t];
        }
    }
    d_functions[i] = sum * solid[t];
}
