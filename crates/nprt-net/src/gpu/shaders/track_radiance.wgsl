// A row's radiance from its tracks' shading outputs (log-radiance): each track's terms, exp of
// three outputs times a weight, 1 or an albedo among the pixel inputs, as the kind table before
// this file says (generated from nprt-net's TrackKind). Shared by the kernels that combine the
// tracks and that take the gradient to a track's outputs (each kernel's source is the table,
// this file, then its own, which binds `features` and the track's outputs `out`).

const FEATURES: u32 = 19u;

// Outputs per row of a track of `kind`: three per term.
fn outputs(kind: u32) -> u32 {
    return 3u * KIND_TERMS[kind];
}

// Term t's weight for row r: 1, or the three pixel inputs the table names.
fn term_weight(kind: u32, t: u32, r: u32) -> vec3<f32> {
    let at = KIND_WEIGHTS[kind][t];
    if (at == ONE_WEIGHT) {
        return vec3<f32>(1.0);
    }
    let f = r * FEATURES + at;
    return vec3<f32>(features[f], features[f + 1u], features[f + 2u]);
}

// exp of each term's three outputs of the track.
fn exps(kind: u32, r: u32) -> array<vec3<f32>, MAX_TERMS> {
    let n = outputs(kind) * r;
    var e: array<vec3<f32>, MAX_TERMS>;
    for (var t = 0u; t < KIND_TERMS[kind]; t++) {
        let i = n + 3u * t;
        e[t] = exp(vec3<f32>(out[i], out[i + 1u], out[i + 2u]));
    }
    return e;
}

fn track_radiance(kind: u32, r: u32, e: array<vec3<f32>, MAX_TERMS>) -> vec3<f32> {
    var c = term_weight(kind, 0u, r) * e[0];
    for (var t = 1u; t < KIND_TERMS[kind]; t++) {
        c += term_weight(kind, t, r) * e[t];
    }
    return c;
}
