//! One light path: Mitsuba 3's `path` integrator for a scene lit only by a distant
//! environment. `max_depth` counts path vertices as Mitsuba does (1: the emitter seen
//! directly; 2: direct illumination; …), Russian roulette starts at `rr_depth`.

use glam::{Vec2, Vec3};
use nprt_scene::{BsdfParams, EnvMap, Scene};
use rand::RngExt;
use rand_pcg::Pcg64Mcg;

use crate::accel::Hit;
use crate::bsdf::Bsdf;
use crate::render::TraceScene;
use crate::shading_frame::Frame3;

/// A surface point seen along a ray, oriented for shading.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub p: Vec3,
    /// Geometric normal, on the same side as the shading normal.
    pub ng: Vec3,
    /// Shading normal; flipped towards the viewer on two-sided materials.
    pub ns: Vec3,
    pub params: BsdfParams,
    /// Index into the scene's materials.
    pub material: usize,
}

/// Power heuristic (β = 2) weight of the strategy with density `a` against `b`.
fn mis(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 {
        a2 / (a2 + b2)
    } else {
        0.0
    }
}

/// Origin just off the surface on the side `dir` leaves towards (Mitsuba's ray epsilon scale).
pub fn offset_origin(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    let eps = (1.0 + p.abs().max_element()) * 1e-4;
    p + ng * eps.copysign(ng.dot(dir))
}

/// Interpolates position, normals and uv at a hit, and evaluates the material there.
pub fn surface_point(scene: &Scene, hit: &Hit, dir: Vec3) -> SurfacePoint {
    let mesh = &scene.meshes[hit.mesh as usize];
    let tri = mesh.indices[hit.tri as usize];
    let w = [1.0 - hit.b1 - hit.b2, hit.b1, hit.b2];
    let lerp3 = |a: &[Vec3]| {
        tri.iter()
            .zip(w)
            .map(|(&i, wi)| a[i as usize] * wi)
            .sum::<Vec3>()
    };
    let p = lerp3(&mesh.positions);
    let v = tri.map(|i| mesh.positions[i as usize]);
    let mut ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or(Vec3::Y);
    let mut ns = if mesh.normals.is_empty() {
        ng
    } else {
        lerp3(&mesh.normals).normalize_or(ng)
    };
    let uv = if mesh.uvs.is_empty() {
        Vec2::ZERO
    } else {
        tri.iter()
            .zip(w)
            .map(|(&i, wi)| mesh.uvs[i as usize] * wi)
            .sum()
    };
    let material = &scene.materials[mesh.material];
    if material.two_sided && ns.dot(dir) > 0.0 {
        ns = -ns;
    }
    if ng.dot(ns) < 0.0 {
        ng = -ng;
    }
    SurfacePoint {
        p,
        ng,
        ns,
        params: material.eval(uv),
        material: mesh.material,
    }
}

/// Radiance carried by one path: all of it, and the direct part (the emitter seen directly
/// plus light that reached the first surface straight from the emitter).
#[derive(Clone, Copy, Debug, Default)]
pub struct PathRadiance {
    pub total: Vec3,
    pub direct: Vec3,
}

pub struct PathSettings {
    pub max_depth: u32,
    pub rr_depth: u32,
}

/// A surface vertex of a path, ready to shade.
struct Vertex<'a> {
    sp: SurfacePoint,
    frame: Frame3,
    wo: Vec3,
    bsdf: Bsdf<'a>,
    /// Throughput up to this vertex.
    beta: Vec3,
    /// Surface bounces before this vertex.
    depth: u32,
}

/// How a path left the scene.
struct Escape {
    dir: Vec3,
    beta: Vec3,
    /// Surface bounces before leaving (0: the camera ray missed).
    depth: u32,
    /// Density of the BSDF sample that left (0 when `depth` is 0).
    pdf: f32,
    /// The last bounce was a delta lobe (glass, a mask's pass-through): no light sample could
    /// have found this direction.
    delta: bool,
}

/// Follows a path by BSDF sampling, calling `at_surface` at each vertex before it scatters,
/// until it leaves the scene (`Some`) or ends on a surface (absorbed, Russian roulette from
/// `rr_depth`, or `max_depth` reached: `None`). The one walk behind both integrators.
fn walk(
    ts: &TraceScene,
    mut origin: Vec3,
    mut dir: Vec3,
    s: &PathSettings,
    rng: &mut Pcg64Mcg,
    mut at_surface: impl FnMut(&Vertex, &mut Pcg64Mcg),
) -> Option<Escape> {
    let (mut beta, mut pdf, mut depth, mut delta) = (Vec3::ONE, 0.0f32, 0u32, false);
    // Product of the relative indices crossed: Russian roulette judges the throughput as if
    // outside, as Mitsuba 3 does.
    let mut eta = 1.0f32;
    loop {
        let Some(hit) = ts.accel.intersect(origin, dir, f32::INFINITY) else {
            return Some(Escape {
                dir,
                beta,
                depth,
                pdf,
                delta,
            });
        };
        if depth + 1 >= s.max_depth {
            return None;
        }
        let sp = surface_point(ts.scene, &hit, dir);
        let frame = Frame3::new(sp.ns);
        let wo = frame.to_local(-dir);
        let bsdf = Bsdf::new(sp.params, ts.coatings[sp.material].as_ref());
        if !bsdf.scatters(wo) {
            return None;
        }
        let v = Vertex {
            sp,
            frame,
            wo,
            bsdf,
            beta,
            depth,
        };
        at_surface(&v, rng);
        let bs = v
            .bsdf
            .sample(wo, Vec2::new(rng.random(), rng.random()), rng.random())?;
        dir = frame.to_world(bs.wi);
        origin = offset_origin(v.sp.p, v.sp.ng, dir);
        beta *= bs.weight;
        pdf = bs.pdf;
        delta = bs.delta;
        eta *= bs.eta;
        depth += 1;
        if depth >= s.rr_depth {
            let q = (beta.max_element() * eta * eta).min(0.95);
            if rng.random::<f32>() >= q {
                return None;
            }
            beta /= q;
        }
    }
}

/// Radiance along one camera ray: BSDF sampling and next-event estimation towards the
/// environment at every vertex, combined by multiple importance sampling.
pub fn trace_path(
    ts: &TraceScene,
    env: &EnvMap,
    origin: Vec3,
    dir: Vec3,
    s: &PathSettings,
    rng: &mut Pcg64Mcg,
) -> PathRadiance {
    let mut out = PathRadiance::default();
    if s.max_depth == 0 {
        return out;
    }
    let escape = walk(ts, origin, dir, s, rng, |v, rng| {
        if !v.bsdf.is_smooth() {
            return;
        }
        let (wi_world, le, light_pdf) =
            env.sample(Vec3::new(rng.random(), rng.random(), rng.random()));
        if light_pdf <= 0.0 {
            return;
        }
        let wi = v.frame.to_local(wi_world);
        let f = v.bsdf.eval(v.wo, wi);
        if f != Vec3::ZERO
            && !ts.accel.occluded(
                offset_origin(v.sp.p, v.sp.ng, wi_world),
                wi_world,
                f32::INFINITY,
            )
        {
            let c = v.beta * f * le * (mis(light_pdf, v.bsdf.pdf(v.wo, wi)) / light_pdf);
            out.total += c;
            if v.depth == 0 {
                out.direct += c;
            }
        }
    });
    if let Some(e) = escape {
        let (le, light_pdf) = env.eval_pdf(e.dir);
        let weight = if e.depth == 0 || e.delta {
            1.0
        } else {
            mis(e.pdf, light_pdf)
        };
        let c = e.beta * le * weight;
        out.total += c;
        if e.depth <= 1 {
            out.direct += c;
        }
    }
    out
}

/// Follows one path by BSDF sampling alone until it leaves the scene; returns the escape
/// direction and the path throughput, or `None` when the path ends on a surface (absorbed,
/// Russian roulette, `max_depth`) or misses the scene from the start (no scattered light).
pub fn trace_escape(
    ts: &TraceScene,
    origin: Vec3,
    dir: Vec3,
    s: &PathSettings,
    rng: &mut Pcg64Mcg,
) -> Option<(Vec3, Vec3)> {
    walk(ts, origin, dir, s, rng, |_, _| {})
        .filter(|e| e.depth > 0)
        .map(|e| (e.dir, e.beta))
}
