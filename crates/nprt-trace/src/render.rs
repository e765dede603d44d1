//! Renders a frame: all cores, deterministic per-pixel random streams (the same seed gives the
//! same image whatever the thread count), a progress bar with ETA.

use glam::{Vec2, Vec3};
use nprt_scene::{Camera, EnvMap, Scattering, Scene, Surface};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

use crate::accel::Accel;
use crate::coating::Coating;
use crate::frame::{Frame, GBuffer, GSample};
use crate::integrator::{
    surface_point, trace_escape, trace_path, CameraRay, PathRadiance, PathSettings,
};

/// Where a pixel's samples go through the film.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelFilter {
    /// Uniformly over the pixel's area (Mitsuba's `box` rfilter): reference renders.
    Box,
    /// Every sample through the pixel centre, so radiance matches the G-buffer exactly
    /// (DESIGN.md's dataset convention).
    Centre,
}

#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub spp: u32,
    /// Mitsuba's `max_depth`; `None` is unlimited.
    pub max_depth: Option<u32>,
    pub rr_depth: u32,
    pub seed: u64,
    pub filter: PixelFilter,
    pub progress: bool,
}

/// A scene ready for tracing: its geometry with an acceleration structure.
pub struct TraceScene<'a> {
    pub scene: &'a Scene,
    pub accel: Accel,
    /// Per material: the coat of a plastic, integrated once here (`None` for the others).
    pub coatings: Vec<Option<Coating>>,
}

impl<'a> TraceScene<'a> {
    pub fn new(scene: &'a Scene) -> Self {
        let coatings = scene
            .materials
            .iter()
            .map(|m| match (m.scattering, &m.surface) {
                (Scattering::Plastic { eta, rough, .. }, Surface::Direct { alpha, .. }) => {
                    Some(Coating::new(eta, alpha.eval(Vec2::ZERO).x, rough))
                }
                _ => None,
            })
            .collect();
        TraceScene {
            scene,
            accel: Accel::new(scene),
            coatings,
        }
    }
}

/// SplitMix64 finaliser: decorrelates per-pixel seeds.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The random stream of pixel `index` under `seed`: independent of thread count and order, so
/// the same seed gives the same image.
fn pixel_rng(seed: u64, index: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(mix(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ mix(index)))
}

struct PixelOut {
    radiance: Vec3,
    direct: Vec3,
    gb: GSample,
}

pub fn render(ts: &TraceScene, camera: &Camera, env: &EnvMap, s: &RenderSettings) -> Frame {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let bar = nprt_io::progress_bar(s.progress, h as u64, "rendering", "rows");
    let path_settings = PathSettings {
        max_depth: s.max_depth.unwrap_or(u32::MAX),
        rr_depth: s.rr_depth,
    };
    let rows: Vec<Vec<PixelOut>> = (0..h)
        .into_par_iter()
        .map(|y| {
            let row = (0..w)
                .map(|x| pixel(ts, camera, env, s, &path_settings, x, y))
                .collect();
            bar.inc(1);
            row
        })
        .collect();
    bar.finish_and_clear();
    let mut f = Frame {
        width: w,
        height: h,
        radiance: vec![],
        direct: vec![],
        gbuffer: GBuffer::default(),
    };
    for p in rows.into_iter().flatten() {
        f.radiance.push(p.radiance);
        f.direct.push(p.direct);
        f.gbuffer.push(p.gb);
    }
    f
}

fn pixel(
    ts: &TraceScene,
    camera: &Camera,
    env: &EnvMap,
    s: &RenderSettings,
    ps: &PathSettings,
    x: usize,
    y: usize,
) -> PixelOut {
    let index = (y * camera.width as usize + x) as u64;
    let mut rng = pixel_rng(s.seed, index);
    let centre = centre_ray(ts, camera, x, y);
    let mut sum = PathRadiance::default();
    for _ in 0..s.spp {
        let ray = match s.filter {
            PixelFilter::Box => {
                let film = Vec2::new(
                    x as f32 + rng.random::<f32>(),
                    y as f32 + rng.random::<f32>(),
                );
                let (o, d) = camera.ray(film);
                CameraRay::trace(ts, o, d)
            }
            PixelFilter::Centre => centre,
        };
        let r = trace_path(ts, env, &ray, ps, &mut rng);
        sum.total += r.total;
        sum.direct += r.direct;
    }
    let n = s.spp.max(1) as f32;
    let gb = gsample(ts, &centre);
    PixelOut {
        radiance: sum.total / n,
        direct: sum.direct / n,
        gb,
    }
}

/// Direct light alone: the map seen directly and light that reached the first surface straight
/// from it, `spp` samples per pixel through the pixel centre (matching the G-buffer). What a
/// model that leaves direct light to the tracer adds at run time: the same image as [`render`]
/// with `max_depth` 2 and [`PixelFilter::Centre`] under the same seed, without the G-buffer.
pub fn render_direct(
    ts: &TraceScene,
    camera: &Camera,
    env: &EnvMap,
    spp: u32,
    seed: u64,
) -> Vec<Vec3> {
    let w = camera.width as usize;
    let ps = PathSettings {
        max_depth: 2,
        rr_depth: u32::MAX,
    };
    (0..w * camera.height as usize)
        .into_par_iter()
        .map(|i| {
            let mut rng = pixel_rng(seed, i as u64);
            let ray = centre_ray(ts, camera, i % w, i / w);
            let sum: Vec3 = (0..spp)
                .map(|_| trace_path(ts, env, &ray, &ps, &mut rng).total)
                .sum();
            sum / spp.max(1) as f32
        })
        .collect()
}

/// The ray through the centre of pixel (x, y), traced.
fn centre_ray(ts: &TraceScene, camera: &Camera, x: usize, y: usize) -> CameraRay {
    let (o, d) = camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
    CameraRay::trace(ts, o, d)
}

/// The G-buffer of the ray through the centre of pixel (x, y).
pub fn primary_sample(ts: &TraceScene, camera: &Camera, x: usize, y: usize) -> GSample {
    gsample(ts, &centre_ray(ts, camera, x, y))
}

/// The G-buffer of what `ray` hits.
fn gsample(ts: &TraceScene, ray: &CameraRay) -> GSample {
    match ray.hit {
        Some(hit) => {
            let sp = surface_point(ts.scene, &hit, ray.dir);
            let (kd, ks, alpha) = sp.params.gbuffer();
            GSample {
                position: sp.p,
                normal: sp.ns,
                view: -ray.dir,
                kd,
                ks,
                alpha,
                mask: 1.0,
            }
        }
        None => GSample::default(),
    }
}

/// Primary rays only: the G-buffer of a whole frame (what a rasteriser would give), in parallel.
pub fn render_gbuffer(ts: &TraceScene, camera: &Camera) -> GBuffer {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let samples: Vec<GSample> = (0..w * h)
        .into_par_iter()
        .map(|i| primary_sample(ts, camera, i % w, i / w))
        .collect();
    let mut g = GBuffer::default();
    for s in samples {
        g.push(s);
    }
    g
}

/// Per-pixel transport of a frame onto a basis of the distant lighting: for each pixel, an
/// estimate of E[path throughput × basis(escape direction)] (one RGB value per basis function),
/// so that radiance under lighting with basis coefficients c is Σ_k T_k ⊙ c_k. Paths sample the
/// BSDF only (the lighting is unknown here); the same seed gives the same transport.
pub fn render_transport(
    ts: &TraceScene,
    camera: &Camera,
    s: &RenderSettings,
    basis_len: usize,
    basis: &(dyn Fn(Vec3, &mut [f32]) + Sync),
) -> Vec<Vec<Vec3>> {
    let w = camera.width as usize;
    let ps = PathSettings {
        max_depth: s.max_depth.unwrap_or(u32::MAX),
        rr_depth: s.rr_depth,
    };
    (0..w * camera.height as usize)
        .into_par_iter()
        .map(|i| {
            let mut rng = pixel_rng(s.seed, i as u64);
            let mut t = vec![Vec3::ZERO; basis_len];
            let mut y_k = vec![0.0; basis_len];
            let ray = centre_ray(ts, camera, i % w, i / w);
            for _ in 0..s.spp {
                if let Some((dir, beta)) = trace_escape(ts, &ray, &ps, &mut rng) {
                    basis(dir, &mut y_k);
                    for (tk, yk) in t.iter_mut().zip(&y_k) {
                        *tk += beta * *yk;
                    }
                }
            }
            let n = s.spp.max(1) as f32;
            t.iter_mut().for_each(|v| *v /= n);
            t
        })
        .collect()
}
