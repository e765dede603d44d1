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
    // K for a linear track (its outputs are K transfer coefficients per term and channel, each
    // term their dot product with the code in `light`); 0: the outputs are log-radiance.
    coefficients: u32,
    // Values between one view's code and the next in `light`, row r's code starting at
    // views[r] · code_stride (training: a code per view); 0: one code for every row.
    code_stride: u32,
}

@group(0) @binding(0) var<uniform> p: Combine;
@group(0) @binding(1) var<storage, read> features: array<f32>;
@group(0) @binding(2) var<storage, read> out: array<f32>;
@group(0) @binding(3) var<storage, read> light: array<f32>;
// Each row's view (u32; read only with code_stride > 0: bind any buffer otherwise).
@group(0) @binding(4) var<storage, read> views: array<u32>;
@group(0) @binding(5) var<storage, read_write> rgb: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let r = id.x + id.y * groups.x * 64u;
    if (r >= p.rows) {
        return;
    }
    let o = 3u * (p.first + r);
    var c = track_radiance(p.kind, r, terms(p.kind, r, p.coefficients, code_at(r, p.code_stride)));
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
