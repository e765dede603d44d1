// The networks' 19 inputs of a block of G-buffer pixels (gbuffer.wgsl's samples, 17 f32 each),
// as nprt-net's pixel_features makes them: the position normalised to [−1, 1] by the model's
// bounds, ωo, ωr (ωo mirrored about n), n, kd, ks, α. Background pixels get zeros (the frame's
// background kernel replaces their radiance).

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

fn put3(r: u32, k: u32, v: vec3<f32>) {
    features[19u * r + k] = v.x;
    features[19u * r + k + 1u] = v.y;
    features[19u * r + k + 2u] = v.z;
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
    let n = sample3(i, 3u);
    let v = sample3(i, 6u);
    put3(r, 0u, (sample3(i, 0u) - p.lo.xyz) / p.extent.xyz * 2.0 - 1.0);
    put3(r, 3u, v);
    put3(r, 6u, 2.0 * dot(n, v) * n - v);
    put3(r, 9u, n);
    put3(r, 12u, sample3(i, 9u));
    put3(r, 15u, sample3(i, 12u));
    features[19u * r + 18u] = samples[17u * i + 15u];
}
