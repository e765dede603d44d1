//! `nprt render`: flags for relighting a camera path under a lighting schedule; the work is
//! `nprt_render::render_sequence`.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use nprt_render::oidn::Oidn;
use nprt_render::{
    render_sequence, Animation, CameraPath, LightingSchedule, Relighter, Sequence,
    DEFAULT_DIRECT_SPP,
};
use nprt_trace::TraceScene;

use crate::{parse_resolution, DeviceArg};

/// Lighting when none is given: maps outside the built-in training set (`builtin` maps).
pub const DEFAULT_LIGHTING: &str = "builtin:sky:30:250:3,builtin:indoor:9";

#[derive(clap::Args)]
pub struct RenderArgs {
    /// Trained model folder (from `nprt train`).
    #[arg(long)]
    pub model: PathBuf,
    /// Output folder: frames/NNNN.png (and .exr with --exr), animation.mp4 or .gif, timings.csv.
    #[arg(long)]
    pub out: PathBuf,
    /// Scene (default: the one the model was trained on); must be that scene.
    #[arg(long)]
    pub scene: Option<String>,
    /// Camera path JSON: {"keyframes": [{"position": [x,y,z], "target": [x,y,z], "fov_x_deg": 60}, …]}
    /// (Catmull-Rom through the keyframes). Default: a sweep through the scene's camera volume.
    #[arg(long)]
    pub camera_path: Option<PathBuf>,
    /// Without --camera-path: sweep through the camera volume of this JSON file instead of the
    /// scene's (its sidecar NAME.camera.json).
    #[arg(long, conflicts_with = "camera_path")]
    pub camera_volume: Option<PathBuf>,
    /// Lighting schedule: comma-separated maps (files or built-in specs), or a JSON file
    /// {"segments": [{"map": …, "weight": 1, "rotation_deg": [0, 90]}]}.
    #[arg(long, default_value = DEFAULT_LIGHTING)]
    pub lighting: String,
    /// Degrees each map of a comma-separated schedule turns about +Y over its segment.
    #[arg(long, default_value_t = 120.0)]
    pub spin: f32,
    /// Number of frames.
    #[arg(long, default_value_t = 48)]
    pub frames: usize,
    /// Frame resolution, N or WxH.
    #[arg(long, default_value = "256", value_parser = parse_resolution)]
    pub res: [u32; 2],
    /// Frames per second of the animation.
    #[arg(long, default_value_t = 24)]
    pub fps: u32,
    /// Exposure of the PNG frames and animation, in stops.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub exposure: f32,
    /// Also write each frame's linear radiance as OpenEXR.
    #[arg(long)]
    pub exr: bool,
    /// Samples per pixel of the direct light, for a model trained with `--direct traced`
    /// (ignored for the others).
    #[arg(long, default_value_t = DEFAULT_DIRECT_SPP)]
    pub direct_spp: u32,
    /// Denoise that direct light with Open Image Denoise (scripts/oidn.sh installs it) before
    /// adding it: far less noise for a few ms per frame (docs/model.md#traced-direct-light).
    #[arg(long)]
    pub denoise_direct: bool,
    #[command(flatten)]
    pub device: DeviceArg,
}

pub fn render(a: RenderArgs) -> Result<()> {
    if a.frames == 0 || a.fps == 0 {
        bail!("--frames and --fps must be at least 1");
    }
    let device = a.device.device()?;
    let model = Relighter::load(&a.model, &device)?;
    let spec = match (&a.scene, model.file.scene.as_str()) {
        (Some(s), _) => s.clone(),
        (None, "") => bail!(
            "model '{}' does not record its scene; give --scene",
            a.model.display()
        ),
        (None, s) => s.to_string(),
    };
    let scene = nprt_data::dataset::load_checked_scene(
        &spec,
        &model.file.scene_hash,
        &format!("model '{}' was trained on", a.model.display()),
    )?;
    let path = match (&a.camera_path, &a.camera_volume) {
        (Some(p), _) => CameraPath::load(p)?,
        (None, Some(v)) => CameraPath::through_volume(&nprt_scene::CameraVolume::load(v)?),
        (None, None) => {
            CameraPath::through_volume(scene.camera_volume.as_ref().with_context(|| {
                format!("scene '{spec}' has no camera volume (no sidecar NAME.camera.json); give --camera-path or --camera-volume")
            })?)
        }
    };
    let lighting = LightingSchedule::parse(&a.lighting, a.spin)?;
    let denoiser = match (a.denoise_direct, model.traces_direct()) {
        (false, _) => None,
        (true, false) => bail!(
            "--denoise-direct: model '{}' does not trace direct light (train it with --direct traced)",
            a.model.display()
        ),
        (true, true) => Some(Oidn::open().context("--denoise-direct needs Open Image Denoise")?),
    };
    let seq = Sequence {
        path: &path,
        lighting: &lighting,
        frames: a.frames,
        resolution: a.res,
        fps: a.fps,
        exposure: a.exposure,
        exr: a.exr,
        direct_spp: a.direct_spp,
        denoiser,
        out: &a.out,
    };
    let [w, h] = a.res;
    println!(
        "nprt render: {} ({}) on {spec}, {} frames at {w}×{h}, lighting {}",
        a.model.display(),
        model.file.config.label(),
        a.frames,
        lighting
            .segments
            .iter()
            .map(|s| s.map.as_str())
            .collect::<Vec<_>>()
            .join(" → ")
    );
    let completion = if model.traces_direct() {
        "direct light"
    } else {
        "background"
    };
    let done = render_sequence(&model, &TraceScene::new(&scene), &seq, |f| {
        let t = &f.timings;
        println!(
            "frame {:>4}/{}: G-buffer {:7.1} ms, encoder {:6.1} ms, network {:8.1} ms, {} {:7.1} ms (ETA {:.0} s)",
            f.index + 1,
            a.frames,
            t.gbuffer_ms,
            t.encoder_ms,
            t.network_ms,
            completion,
            t.direct_ms,
            f.eta_s
        );
    })?;
    let m = done.mean;
    println!(
        "mean per frame: G-buffer {:.1} ms, encoder {:.1} ms (once per lighting change), network {:.1} ms, {completion} {:.1} ms; total {:.1} ms ({:.2} fps)",
        m.gbuffer_ms,
        m.encoder_ms,
        m.network_ms,
        m.direct_ms,
        m.total_ms(),
        1e3 / m.total_ms()
    );
    let kind = match done.animation {
        Animation::Mp4(_) => "MP4 (ffmpeg)",
        Animation::Gif(_) => "GIF (ffmpeg not on PATH or failed)",
    };
    println!(
        "wrote {} frames to {}, animation {} [{kind}]",
        a.frames,
        done.frames_dir.display(),
        done.animation.path().display()
    );
    Ok(())
}
