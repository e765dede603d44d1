// One Adam step over every parameter at once (burn's formulation, which the CPU path uses):
// m ← β1 m + (1 − β1) g, v ← β2 v + (1 − β2) g², θ ← θ − lr · m · c / (√v + ε · √(1 − β2^t))
// with c = √(1 − β2^t) / (1 − β1^t), the bias corrections made on the host. The gradients
// arrive multiplied by the step's loss scale (1, or a power of two in a mixed-precision step,
// so that f16 keeps them) and are divided by it first.

struct Adam {
    count: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    lr: f32,
    beta1: f32,
    beta2: f32,
    // c.
    factor: f32,
    // ε · √(1 − β2^t).
    epsilon: f32,
    // 1 / the loss scale.
    unscale: f32,
    _pad4: f32,
    _pad5: f32,
}

@group(0) @binding(0) var<uniform> p: Adam;
@group(0) @binding(1) var<storage, read> grad: array<f32>;
@group(0) @binding(2) var<storage, read_write> param: array<f32>;
@group(0) @binding(3) var<storage, read_write> m: array<f32>;
@group(0) @binding(4) var<storage, read_write> v: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    if (i >= p.count) {
        return;
    }
    let g = grad[i] * p.unscale;
    let m1 = p.beta1 * m[i] + (1.0 - p.beta1) * g;
    let v1 = p.beta2 * v[i] + (1.0 - p.beta2) * g * g;
    m[i] = m1;
    v[i] = v1;
    param[i] -= p.lr * (m1 * p.factor / (sqrt(v1) + p.epsilon));
}
