// A frame's background: where the G-buffer sees nothing (gbuffer.wgsl's mask 0), the map along
// the pixel-centre ray (map_lookup.wgsl), or zero where the frame's direct light is traced
// later (it holds the map there). After camera_ray.wgsl and map_lookup.wgsl.

struct Background {
    width: u32,
    height: u32,
    // 1: the map; 0: zero.
    fill: u32,
    _pad0: u32,
    x_axis: vec4<f32>,
    y_axis: vec4<f32>,
    z_axis: vec4<f32>,
    origin: vec4<f32>,
    tangents: vec4<f32>,
    map: MapFrame,
}

@group(0) @binding(0) var<uniform> p: Background;
@group(0) @binding(1) var<storage, read> samples: array<f32>;
@group(0) @binding(2) var<storage, read> texels: array<f32>;
@group(0) @binding(3) var<storage, read_write> rgb: array<f32>;

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
        let ray = camera_ray(id.xy, size, p.x_axis.xyz, p.y_axis.xyz, p.z_axis.xyz, p.tangents.xy);
        c = map_radiance(ray, map_to_local(p.map), p.map.size.xy);
    }
    rgb[3u * i] = c.x;
    rgb[3u * i + 1u] = c.y;
    rgb[3u * i + 2u] = c.z;
}
