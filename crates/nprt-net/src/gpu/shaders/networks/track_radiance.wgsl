// A row's radiance from its tracks' shading outputs: each track's terms, times a weight, 1 or
// an albedo among the pixel inputs, as the kind table before this file says (generated from
// nprt-net's TrackKind). A term is exp of three outputs (log-radiance), or for a linear track
// the dot product of its K transfer coefficients per channel with the light code. Shared by
// the kernels that combine the tracks and that take the gradient to a track's outputs (each
// kernel's source is the table, this file, then its own, which binds `features`, the track's
// outputs `out`, the light codes `light` and each row's view `views`).

const FEATURES: u32 = 19u;

// Outputs per row of a track of `kind` with `k` transfer coefficients (0: exp terms): three
// per term, K times that for a linear track.
fn outputs(kind: u32, k: u32) -> u32 {
    return 3u * KIND_TERMS[kind] * max(k, 1u);
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

// Where row r's light code starts in `light`: its view's, `stride` values apart (0: one code).
fn code_at(r: u32, stride: u32) -> u32 {
    if (stride == 0u) {
        return 0u;
    }
    return views[r] * stride;
}

// Coefficient j's three channels of the light code starting at `code`.
fn code_value(code: u32, j: u32) -> vec3<f32> {
    let i = code + 3u * j;
    return vec3<f32>(light[i], light[i + 1u], light[i + 2u]);
}

// Each term's value for row r: exp of its three outputs, or (k > 0, cpu::transport) for a
// linear track Σ_j out[(t·K + j)·3 + c] · code[j·3 + c], the code starting at `code`.
fn terms(kind: u32, r: u32, k: u32, code: u32) -> array<vec3<f32>, MAX_TERMS> {
    let n = outputs(kind, k) * r;
    var e: array<vec3<f32>, MAX_TERMS>;
    for (var t = 0u; t < KIND_TERMS[kind]; t++) {
        if (k == 0u) {
            let i = n + 3u * t;
            e[t] = exp(vec3<f32>(out[i], out[i + 1u], out[i + 2u]));
            continue;
        }
        var s = vec3<f32>(0.0);
        for (var j = 0u; j < k; j++) {
            let i = n + 3u * (t * k + j);
            s += vec3<f32>(out[i], out[i + 1u], out[i + 2u]) * code_value(code, j);
        }
        e[t] = s;
    }
    return e;
}

// Coefficient j of a linear track's part of row r's transfer vector: each term's coefficient j
// times the term's weight (what the radiance is under the code of function j alone).
fn transfer_value(kind: u32, r: u32, k: u32, j: u32) -> vec3<f32> {
    let n = outputs(kind, k) * r;
    var v = vec3<f32>(0.0);
    for (var t = 0u; t < KIND_TERMS[kind]; t++) {
        let i = n + 3u * (t * k + j);
        v += term_weight(kind, t, r) * vec3<f32>(out[i], out[i + 1u], out[i + 2u]);
    }
    return v;
}

fn track_radiance(kind: u32, r: u32, e: array<vec3<f32>, MAX_TERMS>) -> vec3<f32> {
    var c = term_weight(kind, 0u, r) * e[0];
    for (var t = 1u; t < KIND_TERMS[kind]; t++) {
        c += term_weight(kind, t, r) * e[t];
    }
    return c;
}
