// A row's radiance from its tracks' shading outputs (log-radiance): exp, weighted by kd or ks as
// the track's kind says. Shared by the kernels that combine the tracks (frames) and that train
// on them (each kernel's source is this file followed by its own, which binds `features`,
// `out0` and `out1`).

const FEATURES: u32 = 19u;
const KD: u32 = 12u;
const KS: u32 = 15u;

// Outputs per row of a track of `kind`: 0 full (radiance), 1 albedo (kd·L^D + ks·L^S),
// 2 diffuse (kd·L), 3 specular (ks·L).
fn outputs(kind: u32) -> u32 {
    return select(3u, 6u, kind == 1u);
}

fn kd(r: u32) -> vec3<f32> {
    let f = r * FEATURES + KD;
    return vec3<f32>(features[f], features[f + 1u], features[f + 2u]);
}

fn ks(r: u32) -> vec3<f32> {
    let f = r * FEATURES + KS;
    return vec3<f32>(features[f], features[f + 1u], features[f + 2u]);
}

// exp of a track's first three outputs (in out0 or out1), and of its next three for an albedo
// track.
fn exps(kind: u32, out: u32, r: u32) -> array<vec3<f32>, 2> {
    let n = outputs(kind) * r;
    var e: array<vec3<f32>, 2>;
    if (out == 0u) {
        e[0] = exp(vec3<f32>(out0[n], out0[n + 1u], out0[n + 2u]));
        if (kind == 1u) {
            e[1] = exp(vec3<f32>(out0[n + 3u], out0[n + 4u], out0[n + 5u]));
        }
    } else {
        e[0] = exp(vec3<f32>(out1[n], out1[n + 1u], out1[n + 2u]));
    }
    return e;
}

fn track_radiance(kind: u32, r: u32, e: array<vec3<f32>, 2>) -> vec3<f32> {
    switch kind {
        case 0u: { return e[0]; }
        case 1u: { return kd(r) * e[0] + ks(r) * e[1]; }
        case 2u: { return kd(r) * e[0]; }
        default: { return ks(r) * e[0]; }
    }
}
