// EnvMap::sample and eval_pdf on the device: lat-long patches drawn by Walker's alias table
// (nprt-scene's Distribution2D, bound as `table`: per cell its density, keep probability and
// alias) and the solid-angle density of any direction. After map_lookup.wgsl; the shader that
// includes this gives `table_size` (cells per row, rows).

struct MapSample {
    dir: vec3<f32>,
    radiance: vec3<f32>,
    pdf: f32,
}

fn rotate(m: mat3x3<f32>, v: vec3<f32>) -> vec3<f32> {
    return m[0] * v.x + m[1] * v.y + m[2] * v.z;
}

fn cell_density(cell: u32) -> f32 {
    return bitcast<f32>(table[3u * cell]);
}

// Three uniforms → a world direction towards the map, its radiance and density.
fn map_sample(u: vec3<f32>, to_world: mat3x3<f32>, size: vec2<u32>, table_size: vec2<u32>) -> MapSample {
    let n = table_size.x * table_size.y;
    let i = min(u32(u.x * f32(n)), n - 1u);
    var cell = table[3u * i + 2u];
    if u.y < bitcast<f32>(table[3u * i + 1u]) {
        cell = i;
    }
    let fx = clamp(u.x * f32(n) - f32(i), 0.0, 1.0 - 1.1920929e-7);
    let x = cell % table_size.x;
    let y = cell / table_size.x;
    let p = min(
        vec2<f32>((f32(x) + fx) / f32(table_size.x), (f32(y) + u.z) / f32(table_size.y)),
        vec2<f32>(1.0 - 1.1920929e-7),
    );
    let density = cell_density(cell);
    var uv = p;
    uv.x += 0.5 / f32(size.x);
    uv.x -= floor(uv.x);
    let sin_t = precise_sin_cos(uv.y * PI).x;
    if density <= 0.0 || sin_t <= 1e-6 {
        return MapSample(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0), 0.0);
    }
    let dir = rotate(to_world, uv_direction(uv));
    return MapSample(dir, map_radiance_uv(uv, size), density / (2.0 * PI * PI * sin_t));
}

// The map's radiance along world direction `d` and the density map_sample gives it.
fn map_eval_pdf(d: vec3<f32>, to_local: mat3x3<f32>, size: vec2<u32>, table_size: vec2<u32>) -> vec4<f32> {
    let local = rotate(to_local, d);
    let uv = map_uv(local);
    let radiance = map_radiance_uv(uv, size);
    let sin_t = sqrt(local.x * local.x + local.z * local.z);
    if sin_t <= 1e-6 {
        return vec4<f32>(radiance, 0.0);
    }
    var cell_uv = uv;
    cell_uv.x -= 0.5 / f32(size.x);
    cell_uv.x -= floor(cell_uv.x);
    let x = min(u32(cell_uv.x * f32(table_size.x)), table_size.x - 1u);
    let y = min(u32(cell_uv.y * f32(table_size.y)), table_size.y - 1u);
    return vec4<f32>(radiance, cell_density(y * table_size.x + x) / (2.0 * PI * PI * sin_t));
}
