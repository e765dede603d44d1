//! nprt-render: run-time Neural PRT. It owns turning a trained model plus a G-buffer and an
//! environment map into a globally illuminated frame, camera paths and lighting schedules over
//! time, and writing frames and animations. It reads models through nprt-net and traces only
//! primary rays (for the G-buffer, which the GPU frame path rasterises instead) through
//! nprt-trace, and direct light for models that leave
//! it to the tracer, which it can denoise with Open Image Denoise (the one binding, which the
//! evaluation's denoised baselines use too); it must not train networks, write datasets or
//! compute error metrics.
//!
//! ```
//! use nprt_render::{CameraPath, LightingSchedule};
//! use nprt_scene::{load_scene, SceneOptions};
//!
//! // A sequence's camera and lighting: a path through the scene's camera volume, and two
//! // maps, the first spinning for half the frames.
//! let scene = load_scene("builtin:room", &SceneOptions::default())?;
//! let path = CameraPath::through_volume(scene.camera_volume.as_ref().unwrap());
//! let camera = path.camera(0.5, 64, 48);
//! assert_eq!((camera.width, camera.height), (64, 48));
//! let schedule = LightingSchedule::parse("builtin:sky,builtin:indoor:1", 90.0)?;
//! let (map, _rotation_deg) = schedule.at(0, 10);
//! assert_eq!(map, 0);
//! # Ok::<(), anyhow::Error>(())
//! ```

mod animation;
mod denoise;
mod example_view;
mod frame_bench;
mod frame_stages;
mod frame_timings;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod oidn;
mod on_engine;
mod path;
mod relight;
mod render_job;
pub mod schedule;
mod scripted_key;
mod sequence;
#[cfg(feature = "view")]
pub mod view;

pub use animation::{write_animation, Animation};
pub use denoise::{Denoise, DenoiseCheck, DENOISE_CHECK_FILE};
pub use example_view::ExampleView;
pub use frame_bench::{bench_frame, FrameBenchOptions, FrameBenchRow};
pub use frame_stages::{background, DirectSampling, FrameRadiance};
pub use frame_timings::FrameTimings;
pub use nprt_net::Precision;
pub use path::CameraPath;
pub use relight::{FrameCache, Relighter, Still, DEFAULT_DIRECT_SPP};
pub use render_job::{RenderJob, RenderOptions, DEFAULT_LIGHTING};
pub use schedule::LightingSchedule;
pub use scripted_key::ScriptedKey;
pub use sequence::{render_sequence, FrameReport, Sequence, SequenceSummary};
