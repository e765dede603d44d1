// The networks' 19 inputs of a block of G-buffer pixels (GSample's fields, 17 f32 each, as
// nprt-render's rasterised G-buffer leaves them on the device), after pixel_features.wgsl.
// Background pixels get zeros (the frame's background replaces their radiance).

struct Inputs {
    rows: u32,
    // The block's first pixel.
    first: u32,
    _pad0: u32,
    _pad1: u32,
    // The bounds' minimum, and their extent (at least 1e-6 per axis).
    lo: vec4<f32>,
    extent: vec4<f32>,
}

@group(0) @binding(0) var<uniform> p: Inputs;
@group(0) @binding(1) var<storage, read> samples: array<f32>;
@group(0) @binding(2) var<storage, read_write> features: array<f32>;

fn sample3(i: u32, k: u32) -> vec3<f32> {
    return vec3<f32>(samples[17u * i + k], samples[17u * i + k + 1u], samples[17u * i + k + 2u]);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let r = id.x + id.y * groups.x * 64u;
    if r >= p.rows {
        return;
    }
    let i = p.first + r;
    if samples[17u * i + 16u] <= 0.5 {
        for (var k = 0u; k < 19u; k++) {
            features[19u * r + k] = 0.0;
        }
        return;
    }
    pixel_features(r, sample3(i, 0u), sample3(i, 3u), sample3(i, 6u), sample3(i, 9u), sample3(i, 12u), samples[17u * i + 15u], p.lo.xyz, p.extent.xyz);
}
