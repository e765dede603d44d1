//! Per-pixel light transport onto a basis of the distant lighting (what SH PRT precomputes).

use glam::Vec3;
use nprt_scene::Camera;
use rayon::prelude::*;

use crate::integrator::{trace_escape, CameraRay, PathSettings};
use crate::pixel_rng::pixel_rng;
use crate::render::RenderSettings;
use crate::trace_scene::TraceScene;

/// Per-pixel transport of a frame onto a basis of the distant lighting: for each pixel, an
/// estimate of E[path throughput × basis(escape direction)] (one RGB value per basis function),
/// so that radiance under lighting with basis coefficients c is Σ_k T_k ⊙ c_k. `basis(d, depth,
/// out)` writes the `basis_len` values a path escaping along `d` after `depth` surface vertices
/// adds (1: the direct light), so a caller can keep parts of the transport apart. Paths sample
/// the BSDF only (the lighting is unknown here); the same seed gives the same transport.
pub fn render_transport(
    ts: &TraceScene,
    camera: &Camera,
    s: &RenderSettings,
    basis_len: usize,
    basis: &(dyn Fn(Vec3, u32, &mut [f32]) + Sync),
) -> Vec<Vec<Vec3>> {
    let w = camera.width as usize;
    let ps = PathSettings {
        max_depth: s.max_depth.unwrap_or(u32::MAX),
        rr_depth: s.rr_depth,
    };
    (0..w * camera.height as usize)
        .into_par_iter()
        .map(|i| {
            let mut t = vec![Vec3::ZERO; basis_len];
            // A stop requested (nprt_io::interrupt): the caller's check ends the call.
            if nprt_io::interrupt::requested() {
                return t;
            }
            let mut rng = pixel_rng(s.seed, i as u64);
            let mut y_k = vec![0.0; basis_len];
            let ray = CameraRay::centre(ts, camera, i % w, i / w);
            for _ in 0..s.spp {
                if let Some((dir, depth, beta)) = trace_escape(ts, &ray, &ps, &mut rng) {
                    basis(dir, depth, &mut y_k);
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
