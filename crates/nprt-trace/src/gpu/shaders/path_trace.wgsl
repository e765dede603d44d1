// nprt-trace's path tracer on the device (trace_path: BSDF sampling and next-event estimation
// towards the map at every vertex, combined by the power heuristic; Russian roulette from
// `rr_depth`; max_depth counts vertices as Mitsuba does, so 2 is direct light), one thread a
// pixel, `spp` paths through the pixel centre (or jittered over the pixel), their sum over
// `total_spp` written to or added onto `rgb` (a long estimate is split over dispatches), and
// with `keep_direct` their direct part (the map seen directly, and light that reached the
// first surface straight from it, as PathRadiance::direct) onto `direct_rgb` alike. Its random numbers are its own (PCG; the traced direct light's stratified
// as the CPU's), so frames agree with the CPU's within noise, not sample for sample. After camera_ray.wgsl, lerp.wgsl, map_lookup.wgsl,
// map_sampling.wgsl, surface.wgsl, bsdf.wgsl and bvh.wgsl.

struct Params {
    width: u32,
    height: u32,
    // Paths per pixel in this dispatch, and in the whole estimate (the mean's divisor).
    spp: u32,
    total_spp: u32,
    seed: u32,
    max_depth: u32,
    rr_depth: u32,
    // The first path's index (a progressive render's passes draw fresh paths).
    first_path: u32,
    // 1: add the mean onto `rgb`; 0: write it.
    add: u32,
    // 1: uniform over the pixel; 0: through its centre.
    jitter: u32,
    triangle_count: u32,
    keep_direct: u32,
    // 1: the first dimensions of a pixel's `total_spp` paths stratified (traced direct light).
    stratified: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    x_axis: vec4<f32>,
    y_axis: vec4<f32>,
    z_axis: vec4<f32>,
    origin: vec4<f32>,
    tangents: vec4<f32>,
    map: MapFrame,
    // The map's own frame to world (MapFrame's rotation's inverse), as columns.
    to_world_x: vec4<f32>,
    to_world_y: vec4<f32>,
    to_world_z: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> positions: array<f32>;
@group(0) @binding(2) var<storage, read> attributes: array<f32>;
@group(0) @binding(3) var<storage, read> triangles: array<u32>;
@group(0) @binding(4) var<storage, read> materials: array<u32>;
@group(0) @binding(5) var<storage, read> textures: array<u32>;
@group(0) @binding(6) var<storage, read> bitmaps: array<f32>;
@group(0) @binding(7) var<storage, read> bvh_nodes: array<u32>;
@group(0) @binding(8) var<storage, read> bvh_triangles: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read> texels: array<f32>;
@group(0) @binding(10) var<storage, read> table: array<u32>;
@group(0) @binding(11) var<storage, read_write> rgb: array<f32>;
@group(0) @binding(12) var<storage, read_write> direct_rgb: array<f32>;

// One path's radiance: all of it, and its direct part.
struct PathOut {
    total: vec3<f32>,
    direct: vec3<f32>,
}

// PCG's output permutation of a 32-bit LCG step (O'Neill 2014), as a hash and a stream.
fn pcg_hash(x: u32) -> u32 {
    let s = x * 747796405u + 2891336453u;
    let w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}

fn next_uniform(state: ptr<function, u32>) -> f32 {
    *state = *state * 747796405u + 2891336453u;
    let s = *state;
    let w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return f32(((w >> 22u) ^ w) >> 8u) * (1.0 / 16777216.0);
}

// Where a path's uniform numbers come from (nprt-trace's sampler.rs): the PCG stream `state`,
// and, where `count` is not 0 (the traced direct light), the first STRATIFIED_DIMENSIONS
// dimensions of a pixel's `count` paths Latin hypercube sampled: path `sample` takes stratum
// permute(sample, count, dimension_key(key, d)) of dimension d, jittered by the stream.
const STRATIFIED_DIMENSIONS: u32 = 6u;

struct Draws {
    state: u32,
    sample: u32,
    count: u32,
    key: u32,
    dimension: u32,
}

// sampler.rs's `dimension_key`.
fn dimension_key(key: u32, d: u32) -> u32 {
    return pcg_hash(key ^ (d * 0x9e3779b9u));
}

// sampler.rs's `permute`: Kensler's hashed permutation of 0..l, by cycle walking.
fn permute(i_in: u32, l_in: u32, p: u32) -> u32 {
    let l = max(l_in, 1u);
    var w = l - 1u;
    w |= w >> 1u;
    w |= w >> 2u;
    w |= w >> 4u;
    w |= w >> 8u;
    w |= w >> 16u;
    var i = i_in;
    loop {
        i ^= p;
        i *= 0xe170893du;
        i ^= p >> 16u;
        i ^= (i & w) >> 4u;
        i ^= p >> 8u;
        i *= 0x0929eb3fu;
        i ^= p >> 23u;
        i ^= (i & w) >> 1u;
        i *= 1u | (p >> 27u);
        i *= 0x6935fa69u;
        i ^= (i & w) >> 11u;
        i *= 0x74dcb303u;
        i ^= (i & w) >> 2u;
        i *= 0x9e501cc3u;
        i ^= (i & w) >> 2u;
        i *= 0xc860a3dfu;
        i &= w;
        i ^= i >> 5u;
        if i < l {
            break;
        }
    }
    return (i + p % l) % l;
}

fn draw(d: ptr<function, Draws>) -> f32 {
    var state = (*d).state;
    let jitter = next_uniform(&state);
    (*d).state = state;
    let dim = (*d).dimension;
    (*d).dimension = dim + 1u;
    if (*d).count == 0u || dim >= STRATIFIED_DIMENSIONS {
        return jitter;
    }
    let stratum = permute((*d).sample, (*d).count, dimension_key((*d).key, dim));
    return min((f32(stratum) + jitter) / f32((*d).count), 0.99999994);
}

fn power_heuristic(a: f32, b: f32) -> f32 {
    let a2 = a * a;
    let b2 = b * b;
    if a2 + b2 > 0.0 {
        return a2 / (a2 + b2);
    }
    return 0.0;
}

// offset_origin: just off the surface on the side `dir` leaves towards.
fn offset_origin(p: vec3<f32>, ng: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    let eps = (1.0 + max(max(abs(p.x), abs(p.y)), abs(p.z))) * 1e-4;
    return p + ng * select(eps, -eps, dot(ng, dir) < 0.0);
}

fn max_element(v: vec3<f32>) -> f32 {
    return max(max(v.x, v.y), v.z);
}

// trace_ray over the whole ray; nothing in a scene without triangles (bvh.wgsl walks only a
// tree).
fn scene_hit(origin: vec3<f32>, dir: vec3<f32>, first_hit: bool) -> Hit {
    if params.triangle_count == 0u {
        return Hit(0.0, 0u, 0.0, 0.0, false);
    }
    return trace_ray(origin, dir, 3.4e38, first_hit);
}

// The radiance one path carries into the camera along `dir` from `origin`.
fn trace_path(origin_in: vec3<f32>, dir_in: vec3<f32>, draws: ptr<function, Draws>) -> PathOut {
    let size = params.map.size.xy;
    let table_size = vec2<u32>(size.x, size.y - 1u);
    let to_local = map_to_local(params.map);
    let to_world = mat3x3<f32>(params.to_world_x.xyz, params.to_world_y.xyz, params.to_world_z.xyz);
    var total = vec3<f32>(0.0);
    var direct = vec3<f32>(0.0);
    var beta = vec3<f32>(1.0);
    var pdf = 0.0;
    var depth = 0u;
    var delta = false;
    var eta = 1.0;
    var dir = dir_in;
    var hit = scene_hit(origin_in, dir, false);
    loop {
        if !hit.found {
            let lp = map_eval_pdf(dir, to_local, size, table_size);
            var w = 1.0;
            if depth > 0u && !delta {
                w = power_heuristic(pdf, lp.w);
            }
            let c = beta * lp.xyz * w;
            total += c;
            if depth <= 1u {
                direct += c;
            }
            break;
        }
        if depth + 1u >= params.max_depth {
            break;
        }
        let sp = surface_point(hit.tri, hit.b1, hit.b2, dir);
        let frame = tangents(sp.ns);
        let local = mat3x3<f32>(frame[0], frame[1], sp.ns);
        let wo = -dir * local;
        let b = make_bsdf(sp.material, material_params(sp.material, sp.uv), sp.bumped, sp.unbumped * local);
        if !scatters(b, wo) {
            break;
        }
        if is_smooth(b) {
            let u = vec3<f32>(draw(draws), draw(draws), draw(draws));
            let ls = map_sample(u, to_world, size, table_size);
            if ls.pdf > 0.0 {
                let wi = ls.dir * local;
                let f = bsdf_eval(b, wo, wi);
                if any_nonzero(f) && !scene_hit(offset_origin(sp.p, sp.ng, ls.dir), ls.dir, true).found {
                    let c = beta * f * ls.radiance * (power_heuristic(ls.pdf, bsdf_pdf(b, wo, wi)) / ls.pdf);
                    total += c;
                    if depth == 0u {
                        direct += c;
                    }
                }
            }
        }
        let u = vec2<f32>(draw(draws), draw(draws));
        let bs = bsdf_sample(b, wo, u, draw(draws));
        if !bs.ok {
            break;
        }
        dir = local * bs.wi;
        let origin = offset_origin(sp.p, sp.ng, dir);
        beta *= bs.weight;
        pdf = bs.pdf;
        delta = bs.delta;
        eta *= bs.eta;
        depth++;
        if depth >= params.rr_depth {
            let q = min(max_element(beta) * eta * eta, 0.95);
            if draw(draws) >= q {
                break;
            }
            beta /= q;
        }
        // Where the next vertex would end the path, only whether the ray leaves matters.
        hit = scene_hit(origin, dir, depth + 1u >= params.max_depth);
    }
    return PathOut(total, direct);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let i = id.y * params.width + id.x;
    let size = vec2<u32>(params.width, params.height);
    var sum = vec3<f32>(0.0);
    var direct = vec3<f32>(0.0);
    for (var s = 0u; s < params.spp; s++) {
        var state = pcg_hash(params.seed ^ pcg_hash(i ^ pcg_hash(params.first_path + s)));
        var film = vec2<f32>(id.xy) + 0.5;
        if params.jitter == 1u {
            film = vec2<f32>(id.xy) + vec2<f32>(next_uniform(&state), next_uniform(&state));
        }
        let dir = camera_ray_at(film, size, params.x_axis.xyz, params.y_axis.xyz, params.z_axis.xyz, params.tangents.xy);
        let key = pcg_hash(params.seed ^ pcg_hash(i ^ 0x5bd1e995u));
        let count = select(0u, params.total_spp, params.stratified == 1u);
        var draws = Draws(state, params.first_path + s, count, key, 0u);
        let path = trace_path(params.origin.xyz, dir, &draws);
        sum += path.total;
        direct += path.direct;
    }
    let n = f32(max(params.total_spp, 1u));
    var mean = sum / n;
    if params.add == 1u {
        mean += vec3<f32>(rgb[3u * i], rgb[3u * i + 1u], rgb[3u * i + 2u]);
    }
    rgb[3u * i] = mean.x;
    rgb[3u * i + 1u] = mean.y;
    rgb[3u * i + 2u] = mean.z;
    if params.keep_direct == 1u {
        var d = direct / n;
        if params.add == 1u {
            d += vec3<f32>(direct_rgb[3u * i], direct_rgb[3u * i + 1u], direct_rgb[3u * i + 2u]);
        }
        direct_rgb[3u * i] = d.x;
        direct_rgb[3u * i + 1u] = d.y;
        direct_rgb[3u * i + 2u] = d.z;
    }
}
