// The light code's offsets added to the U-Net's bottleneck: per value of views × c planes of
// `hw` values, its plane's offset (views × c).

struct PlaneOffset {
    planes: u32,
    hw: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> p: PlaneOffset;
@group(0) @binding(1) var<storage, read> x: array<f32>;
@group(0) @binding(2) var<storage, read> offset: array<f32>;
@group(0) @binding(3) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    if (i >= p.planes * p.hw) {
        return;
    }
    out[i] = x[i] + offset[i / p.hw];
}
