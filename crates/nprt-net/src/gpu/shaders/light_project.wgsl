// The linear design's light code on the device (LightBasis::project on the host): coefficient
// j of channel c, at j·3 + c, is the sum over the input's texels of function j (already times
// its texel's solid angle) times channel c, one thread a value. Summed with Kahan's
// compensation, as the host sums in f64: a sun is one texel among thousands.

struct LightProject {
    // K: the basis' functions.
    size: u32,
    texels: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> p: LightProject;
// K × texels.
@group(0) @binding(1) var<storage, read> functions: array<f32>;
// The input, channel-major: 3 × texels.
@group(0) @binding(2) var<storage, read> pixels: array<f32>;
@group(0) @binding(3) var<storage, read_write> code: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= 3u * p.size) {
        return;
    }
    let f = (i / 3u) * p.texels;
    let x = (i % 3u) * p.texels;
    var sum = 0.0;
    var lost = 0.0;
    for (var t = 0u; t < p.texels; t++) {
        let y = functions[f + t] * pixels[x + t] - lost;
        let next = sum + y;
        lost = (next - sum) - y;
        sum = next;
    }
    code[i] = sum;
}
