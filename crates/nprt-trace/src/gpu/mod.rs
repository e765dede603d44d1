//! The tracer on the GPU (feature `gpu`): the scene uploaded to nprt-gpu's device with a BVH
//! over its triangles, the G-buffer rasterised there (a visibility pass, then the kept triangle
//! shaded as [`crate::render_gbuffer`] shades a pixel-centre hit), and the path tracer as one
//! WGSL compute shader (`shaders/path_trace.wgsl`: the BVH walk, the BSDFs, the environment
//! map's importance sampling).
//!
//! It computes what the CPU tracer beside it computes, in the same f32 operations (paths with
//! random numbers of their own), and nprt's tests hold the two together (`gpu_gbuffer.rs`,
//! `gpu_trace.rs`); materials stay nprt-scene's, read through the same records the CPU tracer
//! reads.

mod gpu_map;
mod gpu_scene;
mod path_tracer;
mod raster_gbuffer;

pub use gpu_map::{map_frame_words, GpuMap, SameTexels};
pub use gpu_scene::{GpuBvh, GpuScene};
pub use path_tracer::{record_paths, GpuPaths, PathTargets, PATH_TRACE};
pub use raster_gbuffer::{camera_words, RasterGBuffer, GBUFFER};

/// The WGSL parts other stages' kernels put before their own (WGSL has no includes): a camera
/// ray through a pixel, linear interpolation, and a lookup of the environment map.
pub mod wgsl {
    pub const CAMERA_RAY: &str = include_str!("shaders/camera_ray.wgsl");
    pub const LERP: &str = include_str!("shaders/lerp.wgsl");
    pub const MAP_LOOKUP: &str = include_str!("shaders/map_lookup.wgsl");
}
