// A pixel's radiance: its tracks' radiance (track_radiance) summed and multiplied, per
// channel, by the map's divisor and the model's level gain, which the light slot holds after
// the code: read on the device, so that a lighting change needs nothing from the host.

struct Combine {
    rows: u32,
    tracks: u32,
    // Per track: its kind's code (the kind table's index).
    kind0: u32,
    kind1: u32,
    // Index of this block's first row in the frame's rgb.
    first: u32,
    // Index in `light` of the divisor's 3 values, the gain's 3 following.
    scale_at: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> p: Combine;
@group(0) @binding(1) var<storage, read> features: array<f32>;
@group(0) @binding(2) var<storage, read> out0: array<f32>;
@group(0) @binding(3) var<storage, read> out1: array<f32>;
@group(0) @binding(4) var<storage, read> light: array<f32>;
@group(0) @binding(5) var<storage, read_write> rgb: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let r = id.x + id.y * groups.x * 64u;
    if (r >= p.rows) {
        return;
    }
    var c = track_radiance(p.kind0, r, exps(p.kind0, 0u, r));
    if (p.tracks == 2u) {
        c += track_radiance(p.kind1, r, exps(p.kind1, 1u, r));
    }
    let s = p.scale_at;
    c *= vec3<f32>(light[s], light[s + 1u], light[s + 2u]) * vec3<f32>(light[s + 3u], light[s + 4u], light[s + 5u]);
    let o = 3u * (p.first + r);
    rgb[o] = c.x;
    rgb[o + 1u] = c.y;
    rgb[o + 2u] = c.z;
}
