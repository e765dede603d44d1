//! `nprt view`: a window that relights a trained model as you go. The frame is made by the
//! relighter (G-buffer from the tracer's primary rays, the networks on the CPU engine or the
//! GPU frame path's kernels, direct light or background) or, on request, by progressive path
//! tracing of the same view; it is shown through wgpu on the GPU kernels' device, straight from
//! there when they made it (Mesa's software Vulkan
//! under Xvfb in the tests), with the stage timings drawn over it.
//!
//! Owns the window, input and presentation; it must not own rendering: every pixel comes from
//! the relighter or the tracer.

mod compare;
mod live_training;
mod orbit_camera;
mod overlay;
mod presenter;
mod viewer;
mod viewer_keys;
mod viewer_overlay;
mod viewer_state;
mod viewer_training;

pub use live_training::{TrainingJob, DEFAULT_MINUTES};
pub use viewer::run_viewer;
pub use viewer_state::ViewerOptions;
