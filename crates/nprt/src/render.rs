//! `nprt render`: flags for relighting a camera path; the work is `nprt_render::RenderJob`.

use std::path::PathBuf;

use anyhow::Result;
use nprt_net::Engine;
use nprt_render::{Animation, RenderJob, RenderOptions};

use crate::flags::{DeviceArg, Resolution};

/// The defaults every flag shows, from the one place that states them.
fn d() -> RenderOptions {
    RenderOptions::default()
}

#[derive(clap::Args)]
pub struct RenderArgs {
    /// Trained model folder (from `nprt train`).
    #[arg(long)]
    model: PathBuf,
    /// Output folder: frames/NNNN.png (and .exr with --exr), animation.mp4 or .gif, timings.csv.
    #[arg(long)]
    out: PathBuf,
    /// Scene (default: the one the model was trained on); must be that scene.
    #[arg(long)]
    scene: Option<String>,
    /// Camera path JSON: {"keyframes": [{"position": [x,y,z], "target": [x,y,z], "fov_x_deg": 60}, …]}
    /// (Catmull-Rom through the keyframes). Default: a sweep through the scene's camera volume.
    #[arg(long)]
    camera_path: Option<PathBuf>,
    /// Without --camera-path: sweep through the camera volume of this JSON file instead of the
    /// scene's (its sidecar NAME.camera.json).
    #[arg(long, conflicts_with = "camera_path")]
    camera_volume: Option<PathBuf>,
    /// Lighting schedule: comma-separated maps (files or built-in specs), or a JSON file
    /// {"segments": [{"map": …, "weight": 1, "rotation_deg": [0, 90]}]}.
    #[arg(long, default_value_t = d().lighting)]
    lighting: String,
    /// Degrees each map of a comma-separated schedule turns about +Y over its segment.
    #[arg(long, value_parser = crate::flags::finite_f32, default_value_t = d().spin_deg)]
    spin: f32,
    /// Number of frames.
    #[arg(long, default_value_t = d().frames)]
    frames: usize,
    /// Frame resolution, N or WxH.
    #[arg(long, default_value_t = Resolution(d().resolution))]
    res: Resolution,
    /// Frames per second of the animation.
    #[arg(long, default_value_t = d().fps)]
    fps: u32,
    /// Exposure of the PNG frames and animation, in stops.
    #[arg(long, value_parser = crate::flags::finite_f32, default_value_t = d().exposure, allow_hyphen_values = true)]
    exposure: f32,
    /// Also write each frame's linear radiance as OpenEXR.
    #[arg(long)]
    exr: bool,
    /// Samples per pixel of the direct light, for a model trained with `--direct traced`
    /// (ignored for the others).
    #[arg(long, default_value_t = d().direct_spp)]
    direct_spp: u32,
    /// Denoise that direct light with Open Image Denoise (scripts/oidn.sh installs it) before
    /// adding it, far less noise for a few ms per frame (docs/model.md#traced-direct-light):
    /// auto (where OIDN is installed), on (an error without it; the flag alone means on) or
    /// off.
    #[arg(long, default_value_t = d().denoise_direct, num_args = 0..=1, default_missing_value = "on")]
    denoise_direct: nprt_render::Denoise,
    /// The networks' arithmetic: f32, or f16 (weights and activations in f16, sums in f32, on
    /// tensor cores where the adapter has them; the GPU kernels only: --device gpu or wgpu).
    #[arg(long, default_value_t = d().precision)]
    precision: nprt_render::Precision,
    #[command(flatten)]
    device: DeviceArg,
}

impl From<RenderArgs> for RenderOptions {
    fn from(a: RenderArgs) -> Self {
        RenderOptions {
            model: a.model,
            out: a.out,
            scene: a.scene,
            camera_path: a.camera_path,
            camera_volume: a.camera_volume,
            lighting: a.lighting,
            spin_deg: a.spin,
            frames: a.frames,
            resolution: a.res.0,
            fps: a.fps,
            exposure: a.exposure,
            exr: a.exr,
            direct_spp: a.direct_spp,
            denoise_direct: a.denoise_direct,
            precision: a.precision,
        }
    }
}

pub fn command(a: RenderArgs) -> Result<()> {
    let engine = a.device.engine()?;
    run(&a.into(), engine)
}

/// Renders the sequence, printing each frame's time split and the means.
pub fn run(opts: &RenderOptions, engine: Engine) -> Result<()> {
    let job = RenderJob::prepare(opts, engine)?;
    let [w, h] = opts.resolution;
    println!(
        "nprt render: {} ({}; networks on the {}, G-buffer {}) on {}, {} frames at {w}×{h}, lighting {}",
        opts.model.display(),
        job.describe(),
        job.model.networks_on(),
        job.model.gbuffer_on(),
        job.scene_spec,
        opts.frames,
        job.lighting
            .segments
            .iter()
            .map(|s| s.map.as_str())
            .collect::<Vec<_>>()
            .join(" → ")
    );
    let completion = if job.model.traces_direct() {
        "direct light"
    } else {
        "background"
    };
    let done = job.run(|f| {
        let t = &f.timings;
        println!(
            "frame {:>4}/{}: G-buffer {:7.1} ms, encoder {:6.1} ms, network {:8.1} ms, {} {:7.1} ms (ETA {:.0} s)",
            f.index + 1,
            opts.frames,
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
        opts.frames,
        done.frames_dir.display(),
        done.animation.path().display()
    );
    Ok(())
}
