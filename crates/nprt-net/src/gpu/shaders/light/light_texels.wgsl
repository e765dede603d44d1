// The encoder's input on the device, first pass (LightInput::new's lookups): per texel of the
// width × width/2 input, the mean of ss × ss lookups of the map (rotated by `to_local`) spread
// evenly over the texel, rgb per texel. After map_lookup.wgsl.

struct LightTexels {
    width: u32,
    height: u32,
    // Lookups per texel along each axis.
    ss: u32,
    _pad0: u32,
    // The rotated map.
    map: MapFrame,
}

@group(0) @binding(0) var<uniform> p: LightTexels;
@group(0) @binding(1) var<storage, read> texels: array<f32>;
@group(0) @binding(2) var<storage, read_write> rgb: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    if i >= p.width * p.height {
        return;
    }
    let x = f32(i % p.width);
    let y = f32(i / p.width);
    let ss = f32(p.ss);
    let to_local = map_to_local(p.map);
    let size = p.map.size.xy;
    var c = vec3<f32>(0.0);
    for (var s = 0u; s < p.ss * p.ss; s++) {
        let sx = f32(s % p.ss);
        let sy = f32(s / p.ss);
        let uv = vec2<f32>(
            (x + (sx + 0.5) / ss) / f32(p.width),
            (y + (sy + 0.5) / ss) / f32(p.height),
        );
        // EnvMap::eval of a map placed by to_world: its lookup in the map's own frame.
        c += map_radiance(uv_direction(uv), to_local, size);
    }
    c /= ss * ss;
    rgb[3u * i] = c.x;
    rgb[3u * i + 1u] = c.y;
    rgb[3u * i + 2u] = c.z;
}
