// Backward through plane_offset and the ReLU before it: per plane the sum of its gradients `d`
// (the offset's gradient), then, in place, `d` passed on where the ReLU's output `act` is
// positive. One thread per plane (the bottleneck's planes are an eighth of the image's side).

struct OffsetBackward {
    planes: u32,
    hw: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> p: OffsetBackward;
@group(0) @binding(1) var<storage, read> act: array<f32>;
@group(0) @binding(2) var<storage, read_write> d: array<f32>;
@group(0) @binding(3) var<storage, read_write> d_offset: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let plane = id.x + id.y * groups.x * 64u;
    if (plane >= p.planes) {
        return;
    }
    var s = 0.0;
    let base = plane * p.hw;
    for (var j = 0u; j < p.hw; j++) {
        s += d[base + j];
        d[base + j] = select(0.0, d[base + j], act[base + j] > 0.0);
    }
    d_offset[plane] = s;
}
