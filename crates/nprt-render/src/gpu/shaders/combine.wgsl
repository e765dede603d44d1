// A pixel's radiance from its tracks' shading outputs (log-radiance): exp, weighted by kd or ks
// as the track's kind says, summed over the tracks and multiplied by the map's per-channel
// scale (times the model's level gain).

struct Combine {
    rows: u32,
    tracks: u32,
    // Per track: 0 full (radiance), 1 albedo (kd·L^D + ks·L^S), 2 diffuse (kd·L), 3 specular (ks·L).
    kind0: u32,
    kind1: u32,
    // Index of this block's first row in the frame's rgb.
    first: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    scale: vec4<f32>,
}

@group(0) @binding(0) var<uniform> p: Combine;
@group(0) @binding(1) var<storage, read> features: array<f32>;
@group(0) @binding(2) var<storage, read> out0: array<f32>;
@group(0) @binding(3) var<storage, read> out1: array<f32>;
@group(0) @binding(4) var<storage, read_write> rgb: array<f32>;

const FEATURES: u32 = 19u;
const KD: u32 = 12u;
const KS: u32 = 15u;

fn track(kind: u32, r: u32, o: vec3<f32>, o2: vec3<f32>) -> vec3<f32> {
    let f = r * FEATURES;
    let kd = vec3<f32>(features[f + KD], features[f + KD + 1u], features[f + KD + 2u]);
    let ks = vec3<f32>(features[f + KS], features[f + KS + 1u], features[f + KS + 2u]);
    switch kind {
        case 0u: { return exp(o); }
        case 1u: { return kd * exp(o) + ks * exp(o2); }
        case 2u: { return kd * exp(o); }
        default: { return ks * exp(o); }
    }
}

fn outputs(kind: u32) -> u32 {
    return select(3u, 6u, kind == 1u);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let r = id.x + id.y * groups.x * 64u;
    if (r >= p.rows) {
        return;
    }
    let n0 = outputs(p.kind0) * r;
    let o0 = vec3<f32>(out0[n0], out0[n0 + 1u], out0[n0 + 2u]);
    var s0 = o0;
    if (p.kind0 == 1u) {
        s0 = vec3<f32>(out0[n0 + 3u], out0[n0 + 4u], out0[n0 + 5u]);
    }
    var c = track(p.kind0, r, o0, s0);
    if (p.tracks == 2u) {
        let n1 = outputs(p.kind1) * r;
        let o1 = vec3<f32>(out1[n1], out1[n1 + 1u], out1[n1 + 2u]);
        c += track(p.kind1, r, o1, o1);
    }
    c *= p.scale.xyz;
    let o = 3u * (p.first + r);
    rgb[o] = c.x;
    rgb[o + 1u] = c.y;
    rgb[o + 2u] = c.z;
}
