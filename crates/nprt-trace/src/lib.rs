//! The path tracer: ray-scene intersection, the BSDF of DESIGN.md's material model, a path
//! integrator that follows Mitsuba 3's `path` (same `max_depth` meaning, next-event estimation
//! on the environment with power-heuristic MIS, Russian roulette), and per-pixel outputs:
//! radiance, direct-lighting radiance and the G-buffer; and, with feature `gpu`, the same on the
//! GPU ([`gpu`]: the G-buffer rasterised and the path tracer as a WGSL kernel, on nprt-gpu's
//! device), held to the CPU's by tests.
//!
//! It owns everything about light transport and pixels, and reads scenes only through
//! `nprt-scene`; it must not parse files, place dataset cameras or know about networks.
//!
//! ```
//! use nprt_scene::{load_scene, open_envmap, SceneOptions};
//! use nprt_trace::{render, PixelFilter, RenderSettings, TraceScene};
//!
//! let scene = load_scene("builtin:room", &SceneOptions::default())?;
//! let camera = scene.framing_camera().with_resolution(16, 12);
//! let settings = RenderSettings {
//!     spp: 4,
//!     max_depth: None,
//!     rr_depth: scene.rr_depth,
//!     seed: 0,
//!     filter: PixelFilter::Box,
//!     progress: false,
//! };
//! let frame = render(&TraceScene::new(&scene), &camera, &open_envmap("builtin:sky")?, &settings);
//! assert_eq!(frame.radiance.len(), 16 * 12);
//! assert!(frame.radiance.iter().all(|c| c.is_finite()));
//! # Ok::<(), anyhow::Error>(())
//! ```

mod accel;
mod bsdf;
mod cached_path;
mod coating;
mod flat_bvh;
mod frame;
mod gbuffer_pass;
#[cfg(feature = "gpu")]
pub mod gpu;
mod hittable;
mod integrator;
mod microfacet;
mod pixel_rng;
mod reference;
mod render;
pub mod sampler;
mod shading_frame;
mod trace_scene;
mod tracer;
mod transport_pass;

pub use accel::{Accel, Hit};
pub use bsdf::Bsdf;
pub use cached_path::{
    trace_cached, CachePath, CacheRead, CacheVertex, CachedPath, TrainingVertex, SPREAD,
};
pub use coating::Coating;
pub use flat_bvh::{FlatBvh, NODE_WORDS, TRIANGLE_WORDS};
pub use frame::{Frame, GBuffer, GSample};
pub use gbuffer_pass::{primary_sample, render_gbuffer};
pub use integrator::{CameraRay, PathSettings};
pub use pixel_rng::pixel_rng;
pub use reference::{render_reference, Reference, ReferenceOptions, DEFAULT_REFERENCE_SPP};
pub use render::{render, render_direct, PixelFilter, RenderSettings};
pub use trace_scene::TraceScene;
pub use tracer::{TraceDevice, Tracer};
pub use transport_pass::render_transport;
