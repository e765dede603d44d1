//! The G-buffer alone: primary rays through pixel centres, what a rasteriser would give.

use nprt_scene::Camera;
use rayon::prelude::*;

use crate::frame::{GBuffer, GSample};
use crate::integrator::{surface_point, CameraRay};
use crate::trace_scene::TraceScene;

/// The G-buffer of the ray through the centre of pixel (x, y).
pub fn primary_sample(ts: &TraceScene, camera: &Camera, x: usize, y: usize) -> GSample {
    gsample(ts, &CameraRay::centre(ts, camera, x, y))
}

/// The G-buffer of what `ray` hits.
pub(crate) fn gsample(ts: &TraceScene, ray: &CameraRay) -> GSample {
    match ray.hit {
        Some(hit) => {
            let sp = surface_point(&ts.scene, &hit, ray.dir);
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
