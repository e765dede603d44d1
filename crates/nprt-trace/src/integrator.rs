//! One light path: Mitsuba 3's `path` integrator for a scene lit only by a distant
//! environment. `max_depth` counts path vertices as Mitsuba does (1: the emitter seen
//! directly; 2: direct illumination; …), Russian roulette starts at `rr_depth`.

use std::ops::ControlFlow;

use glam::{Vec2, Vec3};
use nprt_scene::{BsdfParams, Camera, EnvMap, Scene};
use rand_pcg::Pcg64Mcg;

use crate::accel::Hit;
use crate::bsdf::Bsdf;
use crate::sampler::Sampler;
use crate::shading_frame::Frame3;
use crate::trace_scene::TraceScene;

/// A surface point seen along a ray, oriented for shading.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub p: Vec3,
    /// Geometric normal, on the same side as the shading normal.
    pub ng: Vec3,
    /// Shading normal (bump-mapped where the material has a bump map); flipped towards the
    /// viewer on two-sided materials.
    pub ns: Vec3,
    /// A bump-mapped point's shading normal before the bump, oriented as `ns`: directions on
    /// opposite sides of the two carry no light ([`Bsdf::with_bump`]).
    pub unbumped: Option<Vec3>,
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

/// Interpolates position, normals and uv at a hit, and evaluates the material there. As in
/// Mitsuba 3, a mesh without texture coordinates is parametrised by its barycentrics, and a
/// degenerate uv mapping falls back to an arbitrary tangent frame.
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
    let face = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or(Vec3::Y);
    let mut ns = if mesh.normals.is_empty() {
        face
    } else {
        lerp3(&mesh.normals).normalize_or(face)
    };
    let (uv, dp_du, dp_dv) = if mesh.uvs.is_empty() {
        (Vec2::new(hit.b1, hit.b2), v[1] - v[0], v[2] - v[0])
    } else {
        let t = tri.map(|i| mesh.uvs[i as usize]);
        let uv = t[0] * w[0] + t[1] * w[1] + t[2] * w[2];
        let (duv0, duv1) = (t[1] - t[0], t[2] - t[0]);
        let (dp0, dp1) = (v[1] - v[0], v[2] - v[0]);
        let det = duv0.x * duv1.y - duv0.y * duv1.x;
        if det != 0.0 {
            (
                uv,
                (dp0 * duv1.y - dp1 * duv0.y) / det,
                (dp1 * duv0.x - dp0 * duv1.x) / det,
            )
        } else {
            let f = Frame3::new(face);
            (uv, f.s, f.t)
        }
    };
    let material = &scene.materials[mesh.material];
    let behind = material.two_sided && ns.dot(dir) > 0.0;
    let mut unbumped = None;
    if let Some(bump) = &material.bump {
        let nb = bump.normal(uv, ns, face, dp_du, dp_dv);
        // Seen from behind, Mitsuba's twosided negates the bumped frame when it is inside the
        // bump map, and mirrors it across the surface when it wraps the bump map.
        let (mut n, base) = match (behind, bump.mirrored_behind) {
            (false, _) => (nb, ns),
            (true, false) => (-nb, -ns),
            (true, true) => (nb - 2.0 * nb.dot(ns) * ns, -ns),
        };
        // Mitsuba's flip_invalid_normals: a bumped normal turned away from the viewer while
        // the surface faces it has its tilt mirrored about the unbumped normal.
        if dir.dot(base) * dir.dot(n) <= 0.0 {
            n = 2.0 * n.dot(base) * base - n;
        }
        ns = n;
        unbumped = Some(base);
    } else if behind {
        ns = -ns;
    }
    let base = unbumped.unwrap_or(ns);
    let ng = if face.dot(base) < 0.0 { -face } else { face };
    SurfacePoint {
        p,
        ng,
        ns,
        unbumped,
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
pub(crate) struct Vertex<'a> {
    pub sp: SurfacePoint,
    pub frame: Frame3,
    pub wo: Vec3,
    pub bsdf: Bsdf<'a>,
    /// Throughput up to this vertex.
    pub beta: Vec3,
    /// Surface bounces before this vertex.
    pub depth: u32,
    /// Length of the segment that reached it, and the density of the BSDF sample that chose
    /// that segment's direction (0 for the camera ray) and whether it was a delta lobe's.
    pub dist: f32,
    pub pdf_in: f32,
    pub delta_in: bool,
}

/// How a path left the scene.
pub(crate) struct Escape {
    pub dir: Vec3,
    pub beta: Vec3,
    /// Surface bounces before leaving (0: the camera ray missed).
    pub depth: u32,
    /// Density of the BSDF sample that left (0 when `depth` is 0).
    pub pdf: f32,
    /// The last bounce was a delta lobe (glass, a mask's pass-through): no light sample could
    /// have found this direction.
    pub delta: bool,
}

/// A ray from the camera and what it hits, traced once and shared by every path that starts
/// along it: all the samples through a pixel's centre (the dataset's convention, the traced
/// direct light, the transport of SH PRT) then save a ray each.
#[derive(Clone, Copy, Debug)]
pub struct CameraRay {
    pub dir: Vec3,
    pub hit: Option<Hit>,
}

impl CameraRay {
    pub fn trace(ts: &TraceScene, origin: Vec3, dir: Vec3) -> Self {
        CameraRay {
            dir,
            hit: ts.accel.intersect(origin, dir, f32::INFINITY),
        }
    }

    /// The ray through the centre of pixel (x, y) of `camera`, traced.
    pub fn centre(ts: &TraceScene, camera: &Camera, x: usize, y: usize) -> Self {
        let (o, d) = camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
        Self::trace(ts, o, d)
    }
}

/// Follows a path by BSDF sampling, calling `at_surface` at each vertex before it scatters,
/// until it leaves the scene (`Some`) or ends on a surface (absorbed, Russian roulette from
/// `rr_depth`, `max_depth` reached, or `at_surface` breaking: `None`). The one walk behind
/// every integrator.
pub(crate) fn walk<S: Sampler>(
    ts: &TraceScene,
    ray: &CameraRay,
    s: &PathSettings,
    rng: &mut S,
    mut at_surface: impl FnMut(&Vertex, &mut S) -> ControlFlow<()>,
) -> Option<Escape> {
    let (mut beta, mut pdf, mut depth, mut delta) = (Vec3::ONE, 0.0f32, 0u32, false);
    // Product of the relative indices crossed: Russian roulette judges the throughput as if
    // outside, as Mitsuba 3 does.
    let mut eta = 1.0f32;
    let (mut dir, mut next) = (ray.dir, ray.hit);
    loop {
        let Some(hit) = next else {
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
        let sp = surface_point(&ts.scene, &hit, dir);
        let frame = Frame3::new(sp.ns);
        let wo = frame.to_local(-dir);
        let bsdf = Bsdf::new(sp.params, ts.coatings[sp.material].as_ref())
            .with_bump(sp.unbumped.map(|n| frame.to_local(n)));
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
            dist: hit.t,
            pdf_in: pdf,
            delta_in: delta,
        };
        if at_surface(&v, rng).is_break() {
            return None;
        }
        let bs = v.bsdf.sample(
            wo,
            Vec2::new(rng.next_f32(), rng.next_f32()),
            rng.next_f32(),
        )?;
        dir = frame.to_world(bs.wi);
        let origin = offset_origin(v.sp.p, v.sp.ng, dir);
        beta *= bs.weight;
        pdf = bs.pdf;
        delta = bs.delta;
        eta *= bs.eta;
        depth += 1;
        if depth >= s.rr_depth {
            let q = (beta.max_element() * eta * eta).min(0.95);
            if rng.next_f32() >= q {
                return None;
            }
            beta /= q;
        }
        // Where the next vertex would end the path (max_depth), only whether the ray leaves
        // matters: an any-hit query, cheaper than the closest hit (traced direct light's every
        // BSDF sample is such a ray).
        next = match depth + 1 >= s.max_depth {
            true if ts.accel.occluded(origin, dir, f32::INFINITY) => return None,
            true => None,
            false => ts.accel.intersect(origin, dir, f32::INFINITY),
        };
    }
}

/// Radiance along one camera ray: BSDF sampling and next-event estimation towards the
/// environment at every vertex, combined by multiple importance sampling.
pub fn trace_path(
    ts: &TraceScene,
    env: &EnvMap,
    ray: &CameraRay,
    s: &PathSettings,
    rng: &mut impl Sampler,
) -> PathRadiance {
    let mut out = PathRadiance::default();
    if s.max_depth == 0 {
        return out;
    }
    let escape = walk(ts, ray, s, rng, |v, rng| {
        let c = next_event(ts, env, v, rng);
        out.total += c;
        if v.depth == 0 {
            out.direct += c;
        }
        ControlFlow::Continue(())
    });
    if let Some(e) = escape {
        let c = escaped(env, &e);
        out.total += c;
        if e.depth <= 1 {
            out.direct += c;
        }
    }
    out
}

/// Next-event estimation at `v`: a light sample towards the environment, weighted by MIS
/// against BSDF sampling (nothing at a vertex with no smooth lobe).
pub(crate) fn next_event(
    ts: &TraceScene,
    env: &EnvMap,
    v: &Vertex,
    rng: &mut impl Sampler,
) -> Vec3 {
    if !v.bsdf.is_smooth() {
        return Vec3::ZERO;
    }
    let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
    let (wi_world, le, light_pdf) = env.sample(u);
    if light_pdf <= 0.0 {
        return Vec3::ZERO;
    }
    let wi = v.frame.to_local(wi_world);
    let f = v.bsdf.eval(v.wo, wi);
    let origin = offset_origin(v.sp.p, v.sp.ng, wi_world);
    if f == Vec3::ZERO || ts.accel.occluded(origin, wi_world, f32::INFINITY) {
        return Vec3::ZERO;
    }
    v.beta * f * le * (mis(light_pdf, v.bsdf.pdf(v.wo, wi)) / light_pdf)
}

/// The environment's light along a path's escape, weighted by MIS against light sampling
/// (fully where no light sample could have found it: the camera ray, or after a delta lobe).
pub(crate) fn escaped(env: &EnvMap, e: &Escape) -> Vec3 {
    let (le, light_pdf) = env.eval_pdf(e.dir);
    let weight = if e.depth == 0 || e.delta {
        1.0
    } else {
        mis(e.pdf, light_pdf)
    };
    e.beta * le * weight
}

/// Follows one path by BSDF sampling alone until it leaves the scene; returns the escape
/// direction, the surface vertices before it (1: direct light) and the path throughput, or `None` when the path ends on a surface (absorbed,
/// Russian roulette, `max_depth`) or misses the scene from the start (no scattered light).
pub fn trace_escape(
    ts: &TraceScene,
    ray: &CameraRay,
    s: &PathSettings,
    rng: &mut Pcg64Mcg,
) -> Option<(Vec3, u32, Vec3)> {
    walk(ts, ray, s, rng, |_, _| ControlFlow::Continue(()))
        .filter(|e| e.depth > 0)
        .map(|e| (e.dir, e.depth, e.beta))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nprt_scene::{Bitmap, BumpMap, Material, Mesh, Texture};
    use std::sync::Arc;

    /// A floor (the rectangle facing +Y) bumped by a height ramp along u, tilting its normal
    /// 45° towards −x, as one material wrapped each way by twosided.
    fn ramp_floor(two_sided: bool, mirrored_behind: bool) -> Scene {
        let mut mesh = Mesh::rectangle();
        mesh.transform(glam::Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2));
        let mut m = Material::diffuse("ramp", Vec3::splat(0.5));
        m.two_sided = two_sided;
        m.bump = Some(BumpMap {
            height: Texture::Bitmap {
                image: Arc::new(Bitmap {
                    width: 4,
                    height: 1,
                    texels: (0..4).map(|i| Vec3::splat(i as f32)).collect(),
                }),
                to_uv: glam::Affine2::IDENTITY,
                factor: Vec3::ONE,
            },
            // Slope 0.5 · 4 per unit u over du/dx = 1/2: 1, so 45°.
            scale: 0.5,
            mirrored_behind,
        });
        let mut scene = Scene::empty("ramp");
        scene.meshes.push(mesh);
        scene.materials.push(m);
        scene
    }

    fn shading_normal(scene: &Scene, dir: Vec3) -> SurfacePoint {
        let hit = Hit {
            t: 1.0,
            mesh: 0,
            tri: 0,
            b1: 0.3,
            b2: 0.2,
        };
        surface_point(scene, &hit, dir.normalize())
    }

    /// Mitsuba 3's bump-mapped frame: tilted by the height's slope; a tilt turned away from
    /// the viewer is mirrored about the unbumped normal (flip_invalid_normals); seen from
    /// behind, a bump map outside twosided negates the frame, one inside it mirrors the frame
    /// across the surface.
    #[test]
    fn bumped_normals_face_the_viewer_as_in_mitsuba() {
        let tilted = Vec3::new(-1.0, 1.0, 0.0).normalize();
        let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-5;
        let front = shading_normal(&ramp_floor(false, false), Vec3::new(0.3, -1.0, 0.1));
        assert!(close(front.ns, tilted), "{}", front.ns);
        assert!(close(front.unbumped.unwrap(), Vec3::Y));
        // Grazing from +x, the viewer sees the tilted normal's back: its tilt is mirrored.
        let grazing = shading_normal(&ramp_floor(false, false), Vec3::new(-1.0, -0.3, 0.0));
        assert!(
            close(grazing.ns, Vec3::new(1.0, 1.0, 0.0).normalize()),
            "{}",
            grazing.ns
        );
        let below = Vec3::new(0.3, 1.0, 0.1);
        let negated = shading_normal(&ramp_floor(true, false), below);
        assert!(close(negated.ns, -tilted), "{}", negated.ns);
        assert!(close(negated.unbumped.unwrap(), -Vec3::Y));
        assert!(
            negated.ng.dot(Vec3::Y) < 0.0,
            "the geometric normal follows"
        );
        let mirrored = shading_normal(&ramp_floor(true, true), below);
        assert!(
            close(mirrored.ns, Vec3::new(-1.0, -1.0, 0.0).normalize()),
            "{}",
            mirrored.ns
        );
    }
}
