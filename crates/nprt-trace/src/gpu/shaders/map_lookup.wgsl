// An environment map's radiance along a direction, as EnvMap::eval computes it: Mitsuba's
// lat-long mapping and bilinear lookup, from the map's texels (rgb f32, row by row) bound as
// `texels` by the shader that includes this. Shared by a frame's background and the encoder's
// input. After lerp.wgsl.

const PI: f32 = 3.14159265358979323846;

// Where a map lies and how large it is, as every kernel that reads a map takes it in its
// parameters (gpu_map.rs's map_frame_words): world to the map's own frame (its rotation's
// inverse) as columns, then its width and height in texels.
struct MapFrame {
    to_local_x: vec4<f32>,
    to_local_y: vec4<f32>,
    to_local_z: vec4<f32>,
    size: vec4<u32>,
}

fn map_to_local(m: MapFrame) -> mat3x3<f32> {
    return mat3x3<f32>(m.to_local_x.xyz, m.to_local_y.xyz, m.to_local_z.xyz);
}

fn texel(x: u32, y: u32, width: u32) -> vec3<f32> {
    let k = 3u * (y * width + x % width);
    return vec3<f32>(texels[k], texels[k + 1u], texels[k + 2u]);
}

// Cephes' single-precision arctangent (a few ulp): the device's own atan2 and acos may be far
// coarser (Vulkan allows 4096 ulp), which moves lookups in a bright map by 1e-4.
fn atan_reduced(x: f32) -> f32 {
    let z = x * x;
    return (((8.05374449538e-2 * z - 1.38776856032e-1) * z + 1.99777106478e-1) * z - 3.33329491539e-1) * z * x + x;
}

fn precise_atan(x: f32) -> f32 {
    let a = abs(x);
    var r: f32;
    if a > 2.414213562373095 {
        r = PI / 2.0 + atan_reduced(-1.0 / a);
    } else if a > 0.4142135623730950 {
        r = PI / 4.0 + atan_reduced((a - 1.0) / (a + 1.0));
    } else {
        r = atan_reduced(a);
    }
    return select(r, -r, x < 0.0);
}

fn precise_atan2(y: f32, x: f32) -> f32 {
    if x == 0.0 {
        if y == 0.0 {
            return 0.0;
        }
        return select(-PI / 2.0, PI / 2.0, y > 0.0);
    }
    let a = precise_atan(y / x);
    if x > 0.0 {
        return a;
    }
    return select(a - PI, a + PI, y >= 0.0);
}

// Cephes' single-precision arcsine on [0, 0.5].
fn asin_reduced(x: f32) -> f32 {
    let z = x * x;
    return ((((4.2163199048e-2 * z + 2.4181311049e-2) * z + 4.5470025998e-2) * z + 7.4953002686e-2) * z + 1.6666752422e-1) * z * x + x;
}

fn precise_acos(x: f32) -> f32 {
    if x < -0.5 {
        return PI - 2.0 * asin_reduced(sqrt(0.5 * (1.0 + x)));
    }
    if x > 0.5 {
        return 2.0 * asin_reduced(sqrt(0.5 * (1.0 - x)));
    }
    return PI / 2.0 - asin_reduced(x);
}

// Cephes' single-precision sine and cosine (a few ulp over the angles a map's coordinates
// make): Vulkan allows the device's own an absolute error of 2^-11, which moves a lookup near a
// sun by 10⁻⁵.
const FOUR_OVER_PI: f32 = 1.27323954473516;
const DP1: f32 = 0.78515625;
const DP2: f32 = 2.4187564849853515625e-4;
const DP3: f32 = 3.77489497744594108e-8;

fn sin_poly(x: f32, z: f32) -> f32 {
    return ((-1.9515295891e-4 * z + 8.3321608736e-3) * z - 1.6666654611e-1) * z * x + x;
}

fn cos_poly(z: f32) -> f32 {
    return ((2.443315711809948e-5 * z - 1.388731625493765e-3) * z + 4.166664568298827e-2) * z * z - 0.5 * z + 1.0;
}

// (sin x, cos x) for 0 ≤ x < 8192: x reduced by multiples of π/4 in three parts.
fn precise_sin_cos(x: f32) -> vec2<f32> {
    var j = u32(x * FOUR_OVER_PI);
    var y = f32(j);
    if (j & 1u) == 1u {
        j += 1u;
        y += 1.0;
    }
    j &= 7u;
    let r = ((x - y * DP1) - y * DP2) - y * DP3;
    let z = r * r;
    let s = sin_poly(r, z);
    let c = cos_poly(z);
    // Octant pairs 0, 2, 4, 6: (s, c), (c, -s), (-s, -c), (-c, s).
    switch j {
        case 2u: {
            return vec2<f32>(c, -s);
        }
        case 4u: {
            return vec2<f32>(-s, -c);
        }
        case 6u: {
            return vec2<f32>(-c, s);
        }
        default: {
            return vec2<f32>(s, c);
        }
    }
}

// uv_to_direction: the map's own direction of lat-long coordinates.
fn uv_direction(uv: vec2<f32>) -> vec3<f32> {
    let t = precise_sin_cos(uv.y * PI);
    let q = precise_sin_cos(uv.x * 2.0 * PI);
    return vec3<f32>(q.x * t.x, t.y, -q.y * t.x);
}

// EnvMap::eval_uv: the bilinear lookup at lat-long coordinates `uv`.
fn map_radiance_uv(uv: vec2<f32>, size: vec2<u32>) -> vec3<f32> {
    let w = f32(size.x);
    var u = uv.x - 0.5 / w;
    u -= floor(u);
    let px = u * w;
    let py = clamp(uv.y, 0.0, 1.0) * f32(size.y - 1u);
    let x0 = min(u32(px), size.x - 1u);
    let y0 = min(u32(py), size.y - 2u);
    let fx = px - f32(x0);
    let fy = py - f32(y0);
    let top = lerp(texel(x0, y0, size.x), texel(x0 + 1u, y0, size.x), fx);
    let bottom = lerp(texel(x0, y0 + 1u, size.x), texel(x0 + 1u, y0 + 1u, size.x), fx);
    return lerp(top, bottom, fy);
}

// direction_to_uv of a direction in the map's own frame.
fn map_uv(d: vec3<f32>) -> vec2<f32> {
    let u = precise_atan2(d.x, -d.z) / (2.0 * PI);
    return vec2<f32>(u - floor(u), precise_acos(clamp(d.y, -1.0, 1.0)) / PI);
}

fn map_radiance(world: vec3<f32>, to_local: mat3x3<f32>, size: vec2<u32>) -> vec3<f32> {
    let d = to_local[0] * world.x + to_local[1] * world.y + to_local[2] * world.z;
    return map_radiance_uv(map_uv(d), size);
}
