//! The viewer's state: what `nprt view` was asked to show, and what it holds between frames
//! (the camera, the lighting, the models or the run trained beside them, the reference, the
//! comparison, the window). What changes it: `viewer` (frames and events), `viewer_keys`,
//! `viewer_overlay` and `viewer_training`.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use glam::Vec3;
use nprt_net::Engine;
use nprt_scene::{EnvMap, Scene};
use nprt_trace::TraceScene;
use winit::event::MouseButton;
use winit::window::Window;

use super::compare::Compare;
use super::live_training::{Training, TrainingJob};
use super::orbit_camera::OrbitCamera;
use super::presenter::Presenter;
use crate::frame_stages::FrameRadiance;
use crate::frame_timings::FrameTimings;
use crate::oidn::Oidn;
use crate::relight::{FrameCache, Relighter};
use crate::Denoise;
use crate::Precision;
use crate::ScriptedKey;

/// What `nprt view` shows and how.
pub struct ViewerOptions {
    /// Model folders of one scene; Tab switches among them.
    pub models: Vec<PathBuf>,
    /// The scene (default: the first model's).
    pub scene: Option<String>,
    /// A camera volume's JSON file to start the camera in (default: the scene's sidecar).
    pub camera_volume: Option<PathBuf>,
    /// Lightings (map files or built-in specs); M switches among them.
    pub maps: Vec<String>,
    pub resolution: [u32; 2],
    /// Where the networks run.
    pub engine: Engine,
    /// Samples per pixel of traced direct light, for models that trace it.
    pub direct_spp: u32,
    /// Whether that light is denoised (O toggles it where OIDN is installed).
    pub denoise_direct: Denoise,
    /// Exposure in stops.
    pub exposure: f32,
    /// Degrees the map turns each frame (0: still until moved).
    pub spin_deg: f32,
    /// Folder of the screenshots the P key takes.
    pub screenshot_dir: PathBuf,
    /// Close after this many frames, writing `screenshot` of the last (scripts and tests).
    pub frames: Option<usize>,
    pub screenshot: Option<PathBuf>,
    /// Start in path-tracing mode (the R key).
    pub reference: bool,
    /// Start with the overlay hidden (the H key).
    pub hide_overlay: bool,
    /// The networks' arithmetic.
    pub precision: Precision,
    /// A run to train beside the frames, showing its newest model (`models` then empty; the
    /// scene, camera volume and, without `maps`, the lightings are its dataset's).
    pub training: Option<TrainingJob>,
    /// Minutes the X key adds to the run.
    pub extend_minutes: f64,
    /// Keys pressed at given times, as `(seconds since the first frame, key)` (scripts and
    /// tests).
    pub keys: Vec<(f64, ScriptedKey)>,
}

impl ViewerOptions {
    /// A window on `job`'s run, with `nprt view`'s defaults: 384×288, the dataset's maps, 4
    /// traced samples a pixel denoised where OIDN is installed, X adding 5 minutes.
    pub fn training(job: TrainingJob) -> Self {
        ViewerOptions {
            models: Vec::new(),
            scene: None,
            camera_volume: None,
            maps: Vec::new(),
            resolution: [384, 288],
            engine: job.engine,
            direct_spp: 4,
            denoise_direct: Denoise::default(),
            exposure: 0.0,
            spin_deg: 0.0,
            screenshot_dir: PathBuf::from("."),
            frames: None,
            screenshot: None,
            reference: false,
            hide_overlay: false,
            precision: Precision::F32,
            training: Some(job),
            extend_minutes: 5.0,
            keys: Vec::new(),
        }
    }
}

/// Progressive path tracing of the current view: the running sum and its samples per pixel.
#[derive(Default)]
pub(super) struct Reference {
    pub(super) sum: Vec<Vec3>,
    pub(super) spp: u32,
    pub(super) pass_ms: f64,
}

pub(super) struct Viewer<'a> {
    pub(super) opts: ViewerOptions,
    pub(super) scene: &'a Scene,
    pub(super) ts: TraceScene<'a>,
    pub(super) models: Vec<Relighter>,
    pub(super) maps: Vec<(String, EnvMap)>,
    pub(super) camera: OrbitCamera,
    pub(super) model: usize,
    pub(super) map: usize,
    pub(super) rotation: f32,
    pub(super) exposure: f32,
    /// The path-traced reference of the view, shown alone (the R key) or compared.
    pub(super) reference: Reference,
    pub(super) show_reference: bool,
    pub(super) compare: Compare,
    /// Where the split view's divider stands, as a share of the width.
    pub(super) divider: f32,
    /// The frame's L1 against the reference, when compared.
    pub(super) l1: Option<f64>,
    /// Whether the model's frame must be made again (the view, the lighting or the weights
    /// changed); else the last is shown again.
    pub(super) stale: bool,
    /// The model's last frame when compared.
    pub(super) model_rgb: Option<Vec<Vec3>>,
    /// When the window's last work (a frame made, a reference pass) ended, and its seconds.
    pub(super) worked: Option<(Instant, f64)>,
    /// The run trained beside the frames, and what the viewer last said of it.
    pub(super) training: Option<Training>,
    pub(super) said: Said,
    pub(super) keys: VecDeque<(f64, ScriptedKey)>,
    /// When the first frame was drawn.
    pub(super) opened: Option<Instant>,
    /// The denoiser of traced direct light, where one is installed and asked for, and whether
    /// it is on (the O key).
    pub(super) oidn: Option<&'static Oidn>,
    pub(super) denoise: bool,
    /// What the current model kept of the last frame: its camera's G-buffer and network
    /// inputs, and the code of its lighting (map and rotation).
    pub(super) cache: FrameCache<(usize, u32)>,
    pub(super) timings: FrameTimings,
    pub(super) frames: usize,
    pub(super) fps: f64,
    pub(super) last_frame: Option<Instant>,
    pub(super) drag: Option<(MouseButton, f64, f64)>,
    /// The drag moves the split view's divider.
    pub(super) on_divider: bool,
    pub(super) cursor: (f64, f64),
    /// The last frame drawn and its overlay (RGBA8 over the frame's top rows; empty when
    /// hidden), for screenshots.
    pub(super) shown: Option<FrameRadiance>,
    pub(super) overlay_rgba: Vec<u8>,
    pub(super) overlay: bool,
    pub(super) message: String,
    pub(super) window: Option<Arc<Window>>,
    pub(super) presenter: Option<Presenter>,
    pub(super) failed: Option<anyhow::Error>,
}

/// What the viewer has printed of its run: the step it was paused at (None while it runs),
/// and the step of its last save.
#[derive(Default)]
pub(super) struct Said {
    pub(super) paused_at: Option<u64>,
    pub(super) saved_at: Option<u64>,
    pub(super) ended: bool,
}
