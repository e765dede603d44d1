//! `nprt render` as a library call: the options (every default stated here), and the choices
//! made from them before any frame is drawn: the model's scene, the camera path, the lighting
//! schedule and the denoiser.

use std::path::PathBuf;

use anyhow::{bail, Result};
use nprt_net::Engine;
use nprt_scene::Scene;
use nprt_trace::TraceScene;

use crate::oidn::Oidn;
use crate::{
    render_sequence, CameraPath, Denoise, DirectSampling, FrameReport, LightingSchedule, Precision,
    Relighter, Sequence, SequenceSummary, DEFAULT_DIRECT_SPP,
};

/// Lighting when none is given: maps outside the built-in training set (`builtin` maps).
pub const DEFAULT_LIGHTING: &str = "builtin:sky:30:250:3,builtin:indoor:9";

/// A relit camera path. `Default` needs only `model` and `out` filled in.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub model: PathBuf,
    pub out: PathBuf,
    /// The scene (default: the one the model records); must be the model's.
    pub scene: Option<String>,
    /// A camera path JSON file (default: a sweep through the scene's camera volume).
    pub camera_path: Option<PathBuf>,
    /// Without a camera path: sweep through this camera-volume file instead of the scene's.
    pub camera_volume: Option<PathBuf>,
    /// Comma-separated maps, or a schedule JSON file.
    pub lighting: String,
    /// Degrees each map of a comma-separated schedule turns about +Y over its segment.
    pub spin_deg: f32,
    pub frames: usize,
    pub resolution: [u32; 2],
    pub fps: u32,
    /// Exposure of the PNG frames and animation, in stops.
    pub exposure: f32,
    /// Also write each frame's linear radiance as OpenEXR.
    pub exr: bool,
    /// Samples per pixel of the direct light of a model that traces it.
    pub direct_spp: u32,
    /// Whether that light is denoised with Open Image Denoise.
    pub denoise_direct: Denoise,
    /// The networks' arithmetic (f16: GPU kernels only).
    pub precision: Precision,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            model: PathBuf::new(),
            out: PathBuf::new(),
            scene: None,
            camera_path: None,
            camera_volume: None,
            lighting: DEFAULT_LIGHTING.into(),
            spin_deg: 120.0,
            frames: 48,
            resolution: [256; 2],
            fps: 24,
            exposure: 0.0,
            exr: false,
            direct_spp: DEFAULT_DIRECT_SPP,
            denoise_direct: Denoise::default(),
            precision: Precision::F32,
        }
    }
}

/// Everything chosen and loaded, ready to draw frames.
pub struct RenderJob {
    pub opts: RenderOptions,
    pub model: Relighter,
    /// The scene's spec, as given or as the model records it.
    pub scene_spec: String,
    pub scene: Scene,
    pub path: CameraPath,
    pub lighting: LightingSchedule,
    denoiser: Option<&'static Oidn>,
}

impl RenderJob {
    /// Loads the model and its scene and makes every choice; errors say what to give.
    pub fn prepare(opts: &RenderOptions, engine: Engine) -> Result<Self> {
        if opts.frames == 0 || opts.fps == 0 {
            bail!("--frames and --fps must be at least 1");
        }
        let [w, h] = opts.resolution;
        engine
            .tracer()
            .check_frame(w, h, &format!("a {w}×{h} frame"))?;
        let mut model = Relighter::load(&opts.model, engine)?;
        model.set_precision(opts.precision)?;
        let scene_spec = match (&opts.scene, model.file.scene.as_str()) {
            (Some(s), _) => s.clone(),
            (None, "") => bail!(
                "model '{}' does not record its scene; give --scene",
                opts.model.display()
            ),
            (None, s) => s.to_string(),
        };
        let scene = nprt_data::dataset::load_checked_scene(
            &scene_spec,
            &model.file.scene_hash,
            &format!("model '{}' was trained on", opts.model.display()),
        )?;
        let path = match (&opts.camera_path, &opts.camera_volume) {
            (Some(p), _) => CameraPath::load(p)?,
            (None, v) => CameraPath::through_volume_of(
                v.as_deref(),
                &scene,
                &scene_spec,
                "give --camera-path or --camera-volume",
            )?,
        };
        let lighting = LightingSchedule::parse(&opts.lighting, opts.spin_deg)?;
        let denoiser = (opts.denoise_direct).denoiser(&model, &opts.model)?;
        Ok(RenderJob {
            opts: opts.clone(),
            model,
            scene_spec,
            scene,
            path,
            lighting,
            denoiser,
        })
    }

    /// How the model's frames are made, in one line ([`Relighter::describe`]).
    pub fn describe(&self) -> String {
        self.model.describe(&DirectSampling {
            spp: self.opts.direct_spp,
            seed: 0,
            denoiser: self.denoiser,
        })
    }

    /// Draws every frame, calling `on_frame` after each, and writes the animation.
    pub fn run(&self, on_frame: impl FnMut(&FrameReport)) -> Result<SequenceSummary> {
        let o = &self.opts;
        let seq = Sequence {
            path: &self.path,
            lighting: &self.lighting,
            frames: o.frames,
            resolution: o.resolution,
            fps: o.fps,
            exposure: o.exposure,
            exr: o.exr,
            direct_spp: o.direct_spp,
            denoiser: self.denoiser,
            out: &o.out,
        };
        render_sequence(&self.model, &TraceScene::new(&self.scene), &seq, on_frame)
    }
}
