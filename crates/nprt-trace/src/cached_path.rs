//! Paths for a radiance cache (the Neural Radiance Cache baseline, Müller et al. 2021): the
//! integrator's path tracing (BSDF sampling and next-event estimation under MIS) with the path
//! ending where a cache is read instead: at its first vertex, or where its footprint has spread
//! enough (their area-spread heuristic). A training path goes on past that point and records,
//! at every vertex, the throughput and the light gathered before it, so that the caller can
//! give each vertex its suffix's radiance as the cache's target. The cache is the caller's: this
//! module says where it is read and with what weight.

use std::f32::consts::PI;
use std::ops::ControlFlow;

use glam::Vec3;
use nprt_scene::EnvMap;
use rand_pcg::Pcg64Mcg;

use crate::integrator::{escaped, next_event, walk, CameraRay, PathSettings, Vertex};
use crate::trace_scene::TraceScene;

/// Müller et al.'s spread threshold: a path reads the cache once its footprint's spread
/// exceeds this share of the primary vertex's.
pub const SPREAD: f32 = 0.01;

/// Where a rendering path reads the cache.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CacheRead {
    /// At the first vertex (NRC-CACHE: the cache gives all the light, as nprt's networks do).
    FirstVertex,
    /// Where the area-spread heuristic ends the path (NRC).
    Spread,
}

/// A path vertex as the cache sees it.
#[derive(Clone, Copy, Debug, Default)]
pub struct CacheVertex {
    pub p: Vec3,
    /// Unit direction the light leaves in, towards the previous vertex.
    pub wo: Vec3,
    /// Unit shading normal.
    pub normal: Vec3,
    pub roughness: f32,
    pub kd: Vec3,
    pub ks: Vec3,
}

impl CacheVertex {
    fn of(v: &Vertex) -> Self {
        CacheVertex {
            p: v.sp.p,
            wo: v.frame.to_world(v.wo),
            normal: v.sp.ns,
            roughness: v.sp.params.alpha,
            kd: v.sp.params.kd,
            ks: v.sp.params.ks,
        }
    }
}

/// A vertex of a training path: what a target is made from.
#[derive(Clone, Copy, Debug)]
pub struct TrainingVertex {
    pub at: CacheVertex,
    /// Throughput up to the vertex.
    pub beta: Vec3,
    /// Light the path gathered before the vertex's own contributions.
    pub before: Vec3,
}

/// A path traced for a cache: the light it gathered, and where it reads the cache with what
/// throughput (`None` where it left the scene or ended first); a training path also lists its
/// vertices.
#[derive(Clone, Debug, Default)]
pub struct CachedPath {
    pub radiance: Vec3,
    pub read: Option<(CacheVertex, Vec3)>,
    pub vertices: Vec<TrainingVertex>,
}

impl CachedPath {
    /// Each recorded vertex's target: the light its suffix carries towards the previous vertex
    /// (the path's light after it, with the cache's `cached` radiance at the read), over the
    /// throughput up to it; vertices whose throughput has all but vanished are left out.
    pub fn targets(&self, cached: Vec3) -> impl Iterator<Item = (CacheVertex, Vec3)> + '_ {
        let total = self.radiance + self.read.map_or(Vec3::ZERO, |(_, beta)| beta * cached);
        self.vertices
            .iter()
            .filter(|v| v.beta.min_element() > 1e-4)
            .map(move |v| (v.at, (total - v.before) / v.beta))
    }
}

/// How a path for the cache is traced.
#[derive(Clone, Copy, Debug)]
pub struct CachePath {
    pub read: CacheRead,
    /// A training path: it goes on past the read for as many vertices again as before it (at
    /// least two), recording every vertex, then reads the cache there.
    pub train: bool,
    /// A training path that never reads the cache: its targets are path tracing's alone, which
    /// keeps the cache's own estimates from drifting (Müller et al. train a sixteenth so).
    pub unbiased: bool,
}

/// The area-spread of a path's footprint (Müller et al.'s a(x1 … xn)): the primary vertex's
/// a0 = d² / (4π |cos|), then √a grows at each later vertex by √(d² / (p |cos|)) (nothing after
/// a delta lobe).
#[derive(Default)]
struct Spread {
    a0: f32,
    root: f32,
}

impl Spread {
    /// Adds vertex `v`; whether the path has spread past the threshold there.
    fn grows_past(&mut self, v: &Vertex) -> bool {
        let cos = v.wo.z.abs().max(1e-4);
        if v.depth == 0 {
            self.a0 = v.dist * v.dist / (4.0 * PI * cos);
            return false;
        }
        if !v.delta_in && v.pdf_in > 0.0 {
            self.root += (v.dist * v.dist / (v.pdf_in * cos)).sqrt();
        }
        self.root * self.root > SPREAD * self.a0
    }
}

/// One path along `ray` for a cache, traced as `how` says.
pub fn trace_cached(
    ts: &TraceScene,
    env: &EnvMap,
    ray: &CameraRay,
    s: &PathSettings,
    how: CachePath,
    rng: &mut Pcg64Mcg,
) -> CachedPath {
    let mut out = CachedPath::default();
    let mut spread = Spread::default();
    // The vertex a rendering path would read the cache at, once passed.
    let mut read_at: Option<u32> = None;
    let escape = walk(ts, ray, s, rng, |v, rng| {
        let spread_out = spread.grows_past(v);
        if read_at.is_none() {
            let here = match how.read {
                CacheRead::FirstVertex => v.depth == 0,
                CacheRead::Spread => spread_out,
            };
            if here {
                read_at = Some(v.depth);
            }
        }
        let end = match (read_at, how.train) {
            (Some(_), false) => true,
            (Some(at), true) => !how.unbiased && v.depth >= 2 * at.max(1),
            (None, _) => false,
        };
        if end {
            out.read = Some((CacheVertex::of(v), v.beta));
            return ControlFlow::Break(());
        }
        if how.train {
            out.vertices.push(TrainingVertex {
                at: CacheVertex::of(v),
                beta: v.beta,
                before: out.radiance,
            });
        }
        out.radiance += next_event(ts, env, v, rng);
        ControlFlow::Continue(())
    });
    if let Some(e) = escape {
        out.radiance += escaped(env, &e);
    }
    out
}
