//! Renders a frame: all cores, deterministic per-pixel random streams (the same seed gives the
//! same image whatever the thread count), a progress bar with ETA.

use glam::{Vec2, Vec3};
use nprt_scene::{Camera, EnvMap};
use rand::RngExt;
use rayon::prelude::*;

use crate::frame::{Frame, GBuffer, GSample};
use crate::gbuffer_pass::gsample;
use crate::integrator::{trace_path, CameraRay, PathRadiance, PathSettings};
use crate::pixel_rng::pixel_rng;
use crate::sampler::StratifiedSampler;
use crate::trace_scene::TraceScene;

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

#[derive(Clone, Default)]
struct PixelOut {
    radiance: Vec3,
    direct: Vec3,
    gb: GSample,
}

impl RenderSettings {
    /// What each path of a render follows: its depth limit and Russian roulette.
    pub fn path(&self) -> PathSettings {
        PathSettings {
            max_depth: self.max_depth.unwrap_or(u32::MAX),
            rr_depth: self.rr_depth,
        }
    }
}

pub fn render(ts: &TraceScene, camera: &Camera, env: &EnvMap, s: &RenderSettings) -> Frame {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let bar = nprt_io::progress_bar(s.progress, h as u64, "rendering", "rows");
    let path_settings = s.path();
    let rows: Vec<Vec<PixelOut>> = (0..h)
        .into_par_iter()
        .map(|y| {
            // A stop requested (nprt_io::interrupt): the rest stays black, and the caller's
            // check ends the call before anything is written of it.
            let row = (0..w)
                .map(|x| match nprt_io::interrupt::requested() {
                    true => PixelOut::default(),
                    false => pixel(ts, camera, env, s, &path_settings, x, y),
                })
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
    let centre = CameraRay::centre(ts, camera, x, y);
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
/// model that leaves direct light to the tracer adds at run time: the image [`render`] makes
/// with `max_depth` 2 and [`PixelFilter::Centre`], in the mean, with each pixel's samples
/// stratified over their light and BSDF samples ([`StratifiedSampler`]): less noise for the
/// same rays (docs/model.md, "The recommended recipe").
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
            let mut sampler = StratifiedSampler::new(pixel_rng(seed, i as u64), spp);
            let ray = CameraRay::centre(ts, camera, i % w, i / w);
            let sum: Vec3 = (0..spp)
                .map(|s| {
                    sampler.start(s);
                    trace_path(ts, env, &ray, &ps, &mut sampler).total
                })
                .sum();
            sum / spp.max(1) as f32
        })
        .collect()
}
