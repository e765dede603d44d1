// The linear design's light codes on the device (LightBasis::project on the host): for each
// view's input, coefficient j of channel c, at j·3 + c of the view's 3K values, is the sum over
// the texels of function j times the texel's solid angle times channel c; one thread a value.
// Summed in blocks with Kahan's compensation over them, as the host sums in f64: a sun is one
// texel among thousands.

struct LightProject {
    // K: the basis' functions.
    size: u32,
    texels: u32,
    views: u32,
    _pad0: u32,
}

@group(0) @binding(0) var<uniform> p: LightProject;
// K × texels: each function's value at each texel's centre.
@group(0) @binding(1) var<storage, read> functions: array<f32>;
// Each texel's solid angle.
@group(0) @binding(2) var<storage, read> solid: array<f32>;
// The inputs, views × 3 × texels (channel-major).
@group(0) @binding(3) var<storage, read> pixels: array<f32>;
@group(0) @binding(4) var<storage, read_write> code: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    let values = 3u * p.size;
    if (i >= p.views * values) {
        return;
    }
    let v = i / values;
    let f = ((i % values) / 3u) * p.texels;
    let x = (3u * v + i % 3u) * p.texels;
    // Blocks of 64 texels summed apart, then the blocks: where a compiler drops the
    // compensation as an algebraic no-op, the blocks still bound the rounding.
    var sum = 0.0;
    var lost = 0.0;
    for (var start = 0u; start < p.texels; start += 64u) {
        var block = 0.0;
        for (var t = start; t < min(start + 64u, p.texels); t++) {
            block += functions[f + t] * solid[t] * pixels[x + t];
        }
        let y = block - lost;
        let next = sum + y;
        lost = (next - sum) - y;
        sum = next;
    }
    code[i] = sum;
}
