// Rays against the scene's triangles on the device: a stack walk of nprt-trace's FlatBvh (the
// nearer child first) with Möller-Trumbore as nprt-trace's Accel tests triangles, so that the
// closest hit is the CPU's. The shader that includes this binds `bvh_nodes` and
// `bvh_triangles` (the leaves' triangles, three vec4 each: v0 and the triangle's index, e1, e2).

const NODE_WORDS: u32 = 8u;
// Deeper than obvhs's Bvh2 builds for the scenes a GPU buffer holds (its default is 96; a
// leaf-collapsed PLOC tree of a million triangles is under 64 deep).
const STACK: u32 = 64u;

struct Hit {
    t: f32,
    tri: u32,
    b1: f32,
    b2: f32,
    found: bool,
}

fn node_min(k: u32) -> vec3<f32> {
    let o = NODE_WORDS * k;
    return vec3<f32>(bitcast<f32>(bvh_nodes[o]), bitcast<f32>(bvh_nodes[o + 1u]), bitcast<f32>(bvh_nodes[o + 2u]));
}

fn node_max(k: u32) -> vec3<f32> {
    let o = NODE_WORDS * k + 4u;
    return vec3<f32>(bitcast<f32>(bvh_nodes[o]), bitcast<f32>(bvh_nodes[o + 1u]), bitcast<f32>(bvh_nodes[o + 2u]));
}

// Entry distance of the ray into node `k`'s box within (0, tmax), or +∞ where it misses.
fn enter(k: u32, origin: vec3<f32>, inv: vec3<f32>, tmax: f32) -> f32 {
    let t0 = (node_min(k) - origin) * inv;
    let t1 = (node_max(k) - origin) * inv;
    let near = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    let far = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), min(max(t0.z, t1.z), tmax));
    return select(3.4e38, near, near <= far);
}

// Tri::intersect of leaf entry `j`: (t, b1, b2) in x, y, z, or t = -1 where the ray misses
// within (0, tmax).
fn hit_triangle(j: u32, origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> vec3<f32> {
    let v0 = bvh_triangles[3u * j].xyz;
    let e1 = bvh_triangles[3u * j + 1u].xyz;
    let e2 = bvh_triangles[3u * j + 2u].xyz;
    let n = cross(e1, e2);
    let c = v0 - origin;
    let r = cross(dir, c);
    let det = dot(n, dir);
    if det == 0.0 {
        return vec3<f32>(-1.0);
    }
    let inv = 1.0 / det;
    let b1 = dot(r, e2) * inv;
    let b2 = dot(r, e1) * inv;
    if b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0 {
        return vec3<f32>(-1.0);
    }
    let t = dot(n, c) * inv;
    if t > 0.0 && t < tmax {
        return vec3<f32>(t, b1, b2);
    }
    return vec3<f32>(-1.0);
}

// The closest hit along origin + t·dir for t in (0, tmax); with `first_hit`, the first found.
fn trace_ray(origin: vec3<f32>, dir: vec3<f32>, tmax_in: f32, first_hit: bool) -> Hit {
    var best = Hit(tmax_in, 0u, 0.0, 0.0, false);
    // A zero component's inverse kept finite, so that a box's slab never gives 0·∞.
    let tiny = vec3<f32>(1e-30);
    let safe = select(dir, select(tiny, -tiny, dir < vec3<f32>(0.0)), abs(dir) < tiny);
    let inv = 1.0 / safe;
    var stack: array<u32, STACK>;
    var top = 0u;
    var k = 0u;
    if enter(0u, origin, inv, best.t) >= 3.4e38 {
        return best;
    }
    loop {
        let count = bvh_nodes[NODE_WORDS * k + 3u];
        let first = bvh_nodes[NODE_WORDS * k + 7u];
        if count > 0u {
            for (var j = first; j < first + count; j++) {
                let h = hit_triangle(j, origin, dir, best.t);
                if h.x > 0.0 {
                    best = Hit(h.x, bitcast<u32>(bvh_triangles[3u * j].w), h.y, h.z, true);
                    if first_hit {
                        return best;
                    }
                }
            }
        } else {
            let a = enter(first, origin, inv, best.t);
            let b = enter(first + 1u, origin, inv, best.t);
            let near = select(first + 1u, first, a <= b);
            let far = select(first, first + 1u, a <= b);
            let t_far = max(a, b);
            if min(a, b) < 3.4e38 {
                if t_far < 3.4e38 && top < STACK {
                    stack[top] = far;
                    top++;
                }
                k = near;
                continue;
            }
        }
        // The next node on the stack that the ray still enters before its closest hit.
        var next = false;
        while top > 0u {
            top--;
            k = stack[top];
            if enter(k, origin, inv, best.t) < 3.4e38 {
                next = true;
                break;
            }
        }
        if !next {
            break;
        }
    }
    return best;
}
