// A frame's background: where the G-buffer sees nothing (gbuffer.wgsl's mask 0), the map along
// the pixel-centre ray (EnvMap::eval: Mitsuba's lat-long mapping and bilinear lookup), or zero
// where the frame's direct light is traced later (it holds the map there). After
// camera_ray.wgsl.

struct Background {
    width: u32,
    height: u32,
    map_width: u32,
    map_height: u32,
    // 1: the map; 0: zero.
    fill: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    x_axis: vec4<f32>,
    y_axis: vec4<f32>,
    z_axis: vec4<f32>,
    origin: vec4<f32>,
    tangents: vec4<f32>,
    // World to the map's own frame (its rotation's inverse), as columns.
    to_local_x: vec4<f32>,
    to_local_y: vec4<f32>,
    to_local_z: vec4<f32>,
}

@group(0) @binding(0) var<uniform> p: Background;
@group(0) @binding(1) var<storage, read> samples: array<f32>;
@group(0) @binding(2) var<storage, read> texels: array<f32>;
@group(0) @binding(3) var<storage, read_write> rgb: array<f32>;

const PI: f32 = 3.14159265358979323846;

fn texel(x: u32, y: u32) -> vec3<f32> {
    let k = 3u * (y * p.map_width + x % p.map_width);
    return vec3<f32>(texels[k], texels[k + 1u], texels[k + 2u]);
}

fn lerp(a: vec3<f32>, b: vec3<f32>, s: f32) -> vec3<f32> {
    return a * (1.0 - s) + b * s;
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

fn map_radiance(world: vec3<f32>) -> vec3<f32> {
    let d = p.to_local_x.xyz * world.x + p.to_local_y.xyz * world.y + p.to_local_z.xyz * world.z;
    let u0 = precise_atan2(d.x, -d.z) / (2.0 * PI);
    let v = precise_acos(clamp(d.y, -1.0, 1.0)) / PI;
    let w = f32(p.map_width);
    var u = (u0 - floor(u0)) - 0.5 / w;
    u -= floor(u);
    let px = u * w;
    let py = clamp(v, 0.0, 1.0) * f32(p.map_height - 1u);
    let x0 = min(u32(px), p.map_width - 1u);
    let y0 = min(u32(py), p.map_height - 2u);
    let fx = px - f32(x0);
    let fy = py - f32(y0);
    let top = lerp(texel(x0, y0), texel(x0 + 1u, y0), fx);
    let bottom = lerp(texel(x0, y0 + 1u), texel(x0 + 1u, y0 + 1u), fx);
    return lerp(top, bottom, fy);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= p.width || id.y >= p.height {
        return;
    }
    let i = id.y * p.width + id.x;
    if samples[17u * i + 16u] > 0.5 {
        return;
    }
    var c = vec3<f32>(0.0);
    if p.fill == 1u {
        let size = vec2<u32>(p.width, p.height);
        c = map_radiance(camera_ray(id.xy, size, p.x_axis.xyz, p.y_axis.xyz, p.z_axis.xyz, p.tangents.xy));
    }
    rgb[3u * i] = c.x;
    rgb[3u * i + 1u] = c.y;
    rgb[3u * i + 2u] = c.z;
}
