// A pixel's radiance, one track per dispatch: the track's radiance (track_radiance) written,
// or added to what the tracks before it wrote; after the last track, multiplied per channel by
// the map's divisor and the model's level gain, which the light slot holds after the code
// (read on the device, so that a lighting change needs nothing from the host). Training sums
// its tracks with it too, unscaled.

struct Combine {
    rows: u32,
    // The track's kind's code (the kind table's index).
    kind: u32,
    // 1: add to `rgb`; 0: this is the first track, write it.
    accumulate: u32,
    // 1: the last track: multiply the sum by the scale in `light`; 0: leave it.
    scaled: u32,
    // Index of this block's first row in `rgb`.
    first: u32,
    // Index in `light` of the divisor's 3 values, the gain's 3 following.
    scale_at: u32,
    // K for a linear track: its outputs are K transfer coefficients per term and channel,
    // each term the dot product of its coefficients with the code at the start of `light`.
    // 0: the outputs are log-radiance.
    coefficients: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> p: Combine;
@group(0) @binding(1) var<storage, read> features: array<f32>;
@group(0) @binding(2) var<storage, read> out: array<f32>;
@group(0) @binding(3) var<storage, read> light: array<f32>;
@group(0) @binding(4) var<storage, read_write> rgb: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let r = id.x + id.y * groups.x * 64u;
    if (r >= p.rows) {
        return;
    }
    let o = 3u * (p.first + r);
    var e: array<vec3<f32>, MAX_TERMS>;
    if (p.coefficients == 0u) {
        e = exps(p.kind, r);
    } else {
        e = transfer_terms(p.kind, r, p.coefficients);
    }
    var c = track_radiance(p.kind, r, e);
    if (p.accumulate == 1u) {
        c = vec3<f32>(rgb[o], rgb[o + 1u], rgb[o + 2u]) + c;
    }
    if (p.scaled == 1u) {
        let s = p.scale_at;
        c *= vec3<f32>(light[s], light[s + 1u], light[s + 2u]) * vec3<f32>(light[s + 3u], light[s + 4u], light[s + 5u]);
    }
    rgb[o] = c.x;
    rgb[o + 1u] = c.y;
    rgb[o + 2u] = c.z;
}

// A linear track's terms (cpu::transport): term t, channel c is
// Σ_j out[(t·K + j)·3 + c] · light[j·3 + c] over the row's K coefficients per term.
fn transfer_terms(kind: u32, r: u32, k: u32) -> array<vec3<f32>, MAX_TERMS> {
    let n = outputs(kind) * k * r;
    var e: array<vec3<f32>, MAX_TERMS>;
    for (var t = 0u; t < KIND_TERMS[kind]; t++) {
        var s = vec3<f32>(0.0);
        for (var j = 0u; j < k; j++) {
            let i = n + 3u * (t * k + j);
            let code = vec3<f32>(light[3u * j], light[3u * j + 1u], light[3u * j + 2u]);
            s += vec3<f32>(out[i], out[i + 1u], out[i + 2u]) * code;
        }
        e[t] = s;
    }
    return e;
}
