// The gradient at a hidden layer's pre-activation from the gradient at its output, in place:
// dy · (z > 0) for ReLU, dy · ω0 cos(ω0 z) for SIREN.

struct ActivationBackward {
    count: u32,
    // 1: ReLU, 2: SIREN.
    activation: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> p: ActivationBackward;
@group(0) @binding(1) var<storage, read> z: array<f32>;
@group(0) @binding(2) var<storage, read_write> dy: array<f32>;

const OMEGA_0: f32 = 30.0;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    if (i >= p.count) {
        return;
    }
    if (p.activation == 1u) {
        dy[i] = select(0.0, dy[i], z[i] > 0.0);
    } else {
        dy[i] *= OMEGA_0 * cos(OMEGA_0 * z[i]);
    }
}
