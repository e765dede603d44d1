// The light model's input on the device, second pass (LightInput::with_texels'
// normalisation), one workgroup: the texels' mean per channel (each thread adds every 256th
// texel in order, then a fixed tree), the divisor MapNorm::scale makes of it, and each channel
// plane of the input, ln(1 + c / scale) for the encoder or c / scale for a basis (Texels),
// channel-major as the light model reads it. The divisor is written to `scale`.

struct LightNormalise {
    texels: u32,
    // 0: MapNorm::Mean (one divisor, the mean over channels); 1: MapNorm::Channel.
    norm: u32,
    // 1: Texels::Log; 0: Texels::Linear.
    log: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> p: LightNormalise;
@group(0) @binding(1) var<storage, read> rgb: array<f32>;
@group(0) @binding(2) var<storage, read_write> pixels: array<f32>;
@group(0) @binding(3) var<storage, read_write> scale: array<f32>;

const THREADS: u32 = 256u;

var<workgroup> sums: array<vec3<f32>, 256>;

fn texel(i: u32) -> vec3<f32> {
    return vec3<f32>(rgb[3u * i], rgb[3u * i + 1u], rgb[3u * i + 2u]);
}

// ln(1 + x) without the rounding of 1 + x for small x (Goldberg's correction).
fn log_1p(x: f32) -> f32 {
    let u = 1.0 + x;
    if u == 1.0 {
        return x;
    }
    return log(u) * (x / (u - 1.0));
}

@compute @workgroup_size(256)
fn main(@builtin(local_invocation_index) t: u32) {
    var s = vec3<f32>(0.0);
    for (var i = t; i < p.texels; i += THREADS) {
        s += texel(i);
    }
    sums[t] = s;
    workgroupBarrier();
    for (var half = THREADS / 2u; half > 0u; half /= 2u) {
        if t < half {
            sums[t] += sums[t + half];
        }
        workgroupBarrier();
    }
    let mean = sums[0] / f32(p.texels);
    var d = mean;
    if p.norm == 0u {
        d = vec3<f32>((mean.x + mean.y + mean.z) / 3.0);
    }
    // f32's smallest normal, as MapNorm::scale clamps.
    d = max(d, vec3<f32>(1.17549435e-38));
    if t == 0u {
        scale[0] = d.x;
        scale[1] = d.y;
        scale[2] = d.z;
    }
    for (var i = t; i < p.texels; i += THREADS) {
        var c = texel(i) / d;
        if p.log == 1u {
            c = vec3<f32>(log_1p(c.x), log_1p(c.y), log_1p(c.z));
        }
        pixels[i] = c.x;
        pixels[p.texels + i] = c.y;
        pixels[2u * p.texels + i] = c.z;
    }
}
