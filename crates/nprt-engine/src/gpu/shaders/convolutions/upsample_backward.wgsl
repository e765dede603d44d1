// The adjoint of upsample_concat's up-sampling: per value of `x` (views × c_x × h × w) the sum
// of its 2 × 2 block's gradients in d_cat (views × (c_x + c_skip) × 2h × 2w), in row order as
// the CPU engine adds them, passed on where `act` (x, a ReLU's output) is positive.

@group(0) @binding(0) var<uniform> p: Upsample;
@group(0) @binding(1) var<storage, read> d_cat: array<f32>;
@group(0) @binding(2) var<storage, read> act: array<f32>;
@group(0) @binding(3) var<storage, read_write> d_x: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    let hw = p.h * p.w;
    if (i >= p.views * p.c_x * hw) {
        return;
    }
    let view = i / (p.c_x * hw);
    let c = (i / hw) % p.c_x;
    let y = (i / p.w) % p.h;
    let x = i % p.w;
    let w2 = 2u * p.w;
    let base = (view * (p.c_x + p.c_skip) + c) * 4u * hw + 2u * y * w2 + 2u * x;
    let s = ((d_cat[base] + d_cat[base + 1u]) + d_cat[base + w2]) + d_cat[base + w2 + 1u];
    d_x[i] = select(0.0, s, act[i] > 0.0);
}
