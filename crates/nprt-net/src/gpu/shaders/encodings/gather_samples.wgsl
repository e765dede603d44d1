// A batch gathered on the device from the dataset's records held there (docs/dataset.md,
// "Packed datasets"): per sample, its record decoded as nprt-data's PackedPixel::decode does
// and made into the 19 network inputs as nprt-net's pixel_features does (in the same f32
// operations, rounded as the device rounds a division, a square root and a multiply-add), its radiance, its
// view's map scale and its view within the batch. One dispatch per shard of records; a sample
// whose record lies in another shard is left to that shard's dispatch. After
// pixel_features.wgsl.

struct Gather {
    rows: u32,
    // The shard's first record and its records.
    first: u32,
    count: u32,
    _pad: u32,
    // The pack's bounds: their minimum, extent (max − min) and the extent the position is
    // normalised by (at least 1e-6 per axis).
    lo: vec4<f32>,
    extent: vec4<f32>,
    normaliser: vec4<f32>,
}

@group(0) @binding(0) var<uniform> p: Gather;
// 10 words per record: position u16 × 3, normal i16 × 2, view i16 × 2, kd f16 × 3, ks f16 × 3,
// α f16, radiance f32 × 3.
@group(0) @binding(1) var<storage, read> records: array<u32>;
// Per sample: its record's index in the whole dataset, and its view within the batch.
@group(0) @binding(2) var<storage, read> picks: array<u32>;
// Per view of the batch: its index among the dataset's views.
@group(0) @binding(3) var<storage, read> views: array<u32>;
// Per dataset view: its map's scale, 3 each.
@group(0) @binding(4) var<storage, read> scales: array<f32>;
@group(0) @binding(5) var<storage, read_write> features: array<f32>;
@group(0) @binding(6) var<storage, read_write> radiance: array<f32>;
@group(0) @binding(7) var<storage, read_write> scale: array<f32>;
@group(0) @binding(8) var<storage, read_write> view: array<u32>;

// The record's `k`-th 16-bit half.
fn half_word(base: u32, k: u32) -> u32 {
    return (records[base + k / 2u] >> (16u * (k % 2u))) & 0xffffu;
}

fn signed_half(base: u32, k: u32) -> f32 {
    let h = half_word(base, k);
    return f32(i32(h << 16u) >> 16u);
}

// An f16 to f32, subnormals kept (the host's decode keeps them).
fn f16_value(h: u32) -> f32 {
    let sign = (h & 0x8000u) << 16u;
    let exponent = (h >> 10u) & 0x1fu;
    let mantissa = h & 0x3ffu;
    if exponent == 0u {
        let magnitude = f32(mantissa) * 5.9604645e-8;
        return select(magnitude, -magnitude, sign != 0u);
    }
    if exponent == 31u {
        return bitcast<f32>(sign | 0x7f800000u | (mantissa << 13u));
    }
    return bitcast<f32>(sign | ((exponent + 112u) << 23u) | (mantissa << 13u));
}

fn f16_vec3(base: u32, k: u32) -> vec3<f32> {
    return vec3<f32>(f16_value(half_word(base, k)), f16_value(half_word(base, k + 1u)), f16_value(half_word(base, k + 2u)));
}

// ±1 per coordinate, +1 at zero.
fn sign_of(v: vec2<f32>) -> vec2<f32> {
    return select(vec2<f32>(-1.0), vec2<f32>(1.0), v >= vec2<f32>(0.0));
}

fn from_octahedral(base: u32, k: u32) -> vec3<f32> {
    let q = vec2<f32>(signed_half(base, k), signed_half(base, k + 1u)) / 32767.0;
    let z = 1.0 - abs(q.x) - abs(q.y);
    var xy = q;
    if z < 0.0 {
        xy = (vec2<f32>(1.0) - vec2<f32>(abs(q.y), abs(q.x))) * sign_of(q);
    }
    return normalize(vec3<f32>(xy, z));
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = id.x + id.y * groups.x * 64u;
    if i >= p.rows {
        return;
    }
    let record = picks[2u * i];
    if record < p.first || record - p.first >= p.count {
        return;
    }
    let base = 10u * (record - p.first);
    let unit = vec3<f32>(f32(half_word(base, 0u)), f32(half_word(base, 1u)), f32(half_word(base, 2u))) / 65535.0;
    let position = p.lo.xyz + unit * p.extent.xyz;
    let alpha = f16_value(half_word(base, 13u));
    pixel_features(i, position, from_octahedral(base, 3u), from_octahedral(base, 5u), f16_vec3(base, 7u), f16_vec3(base, 10u), alpha, p.lo.xyz, p.normaliser.xyz);
    for (var c = 0u; c < 3u; c++) {
        radiance[3u * i + c] = bitcast<f32>(records[base + 7u + c]);
    }
    let local = picks[2u * i + 1u];
    let global = views[local];
    for (var c = 0u; c < 3u; c++) {
        scale[3u * i + c] = scales[3u * global + c];
    }
    view[i] = local;
}
