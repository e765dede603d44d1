// The G-buffer from the visibility pass: per pixel, the centre ray (as Camera::ray makes it)
// intersected with the triangle the rasteriser kept (Möller-Trumbore as nprt-trace's Accel),
// then the surface point (surface.wgsl) and the material's (kd, ks, α) as BsdfParams::gbuffer
// records them. Writes GSample's fields, 17 f32 per pixel: position, normal, ωo, kd, ks, α,
// mask; zeros on the background. After camera_ray.wgsl, lerp.wgsl and surface.wgsl.

struct Params {
    width: u32,
    height: u32,
    pad0: u32,
    pad1: u32,
    // The camera's to_world columns (x, y, z axes and origin), and tan of the half field of
    // view along x and y.
    x_axis: vec4<f32>,
    y_axis: vec4<f32>,
    z_axis: vec4<f32>,
    origin: vec4<f32>,
    tangents: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var visible: texture_2d<u32>;
@group(0) @binding(2) var<storage, read> positions: array<f32>;
@group(0) @binding(3) var<storage, read> attributes: array<f32>;
@group(0) @binding(4) var<storage, read> triangles: array<u32>;
@group(0) @binding(5) var<storage, read> materials: array<u32>;
@group(0) @binding(6) var<storage, read> textures: array<u32>;
@group(0) @binding(7) var<storage, read> bitmaps: array<f32>;
@group(0) @binding(8) var<storage, read_write> gbuffer: array<f32>;

fn write(i: u32, k: u32, v: vec3<f32>) {
    gbuffer[17u * i + k] = v.x;
    gbuffer[17u * i + k + 1u] = v.y;
    gbuffer[17u * i + k + 2u] = v.z;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let i = id.y * params.width + id.x;
    let seen = textureLoad(visible, vec2<u32>(id.x, id.y), 0).x;
    if seen == 0u {
        for (var k = 0u; k < 17u; k++) {
            gbuffer[17u * i + k] = 0.0;
        }
        return;
    }
    let tri = seen - 1u;
    let size = vec2<u32>(params.width, params.height);
    let dir = camera_ray(id.xy, size, params.x_axis.xyz, params.y_axis.xyz, params.z_axis.xyz, params.tangents.xy);
    let v0 = position(triangles[4u * tri]);
    let v1 = position(triangles[4u * tri + 1u]);
    let v2 = position(triangles[4u * tri + 2u]);
    // Möller-Trumbore's barycentrics, as the tracer computes them.
    let e1 = v0 - v1;
    let e2 = v2 - v0;
    let c = v0 - params.origin.xyz;
    let r = cross(dir, c);
    let inv = 1.0 / dot(cross(e1, e2), dir);
    let sp = surface_point(tri, dot(r, e2) * inv, dot(r, e1) * inv, dir);
    let mp = material_params(sp.material, sp.uv);
    let m = sp.material;
    let fresnel = vec3<f32>(
        bitcast<f32>(material_word(m, 7u)),
        bitcast<f32>(material_word(m, 8u)),
        bitcast<f32>(material_word(m, 9u)),
    );
    write(i, 0u, sp.p);
    write(i, 3u, sp.ns);
    write(i, 6u, -dir);
    // Held to [0, 1] as BsdfParams::gbuffer holds them.
    write(i, 9u, clamp(mp.kd * mp.opacity, vec3(0.0), vec3(1.0)));
    write(i, 12u, clamp(mp.ks * fresnel * mp.opacity, vec3(0.0), vec3(1.0)));
    gbuffer[17u * i + 15u] = min(mp.alpha, 1.0);
    gbuffer[17u * i + 16u] = 1.0;
}
