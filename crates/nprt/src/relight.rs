//! `nprt render`: a trained model relighting a camera path under a lighting schedule.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use nprt_net::Device;
use nprt_render::{background, write_animation, write_png, Animation, CameraPath, FrameTimings, LightingSchedule, Relighter};
use nprt_trace::{render_gbuffer, TraceScene};

use crate::{check_writable, parse_resolution};

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
}

pub fn render(a: RenderArgs) -> Result<()> {
    if a.frames == 0 || a.fps == 0 {
        bail!("--frames and --fps must be at least 1");
    }
    let device = Device::flex();
    let model = Relighter::load(&a.model, &device)?;
    let spec = match (&a.scene, model.file.scene.as_str()) {
        (Some(s), _) => s.clone(),
        (None, "") => bail!("model '{}' does not record its scene; give --scene", a.model.display()),
        (None, s) => s.to_string(),
    };
    let scene = nprt_data::dataset::load_checked_scene(
        &spec,
        &model.file.scene_hash,
        &format!("model '{}' was trained on", a.model.display()),
    )?;
    let path = match &a.camera_path {
        Some(p) => CameraPath::load(p)?,
        None => CameraPath::through_volume(scene.camera_volume.as_ref().with_context(|| {
            format!("scene '{spec}' has no camera volume; give --camera-path")
        })?),
    };
    let schedule = LightingSchedule::parse(&a.lighting, a.spin)?;
    let frames_dir = a.out.join("frames");
    check_writable(&frames_dir.join("x"))?;
    let ts = TraceScene::new(&scene);
    let [w, h] = a.res;
    println!(
        "nprt render: {} ({}) on {spec}, {} frames at {w}×{h}, lighting {}",
        a.model.display(),
        model.file.config.design.name(),
        a.frames,
        schedule.segments.iter().map(|s| s.map.as_str()).collect::<Vec<_>>().join(" → ")
    );
    let mut csv = String::from("frame,map,rotation_deg,gbuffer_ms,encoder_ms,network_ms,total_ms\n");
    let mut pngs = Vec::new();
    let mut sum = FrameTimings::default();
    let mut last: Option<(usize, f32)> = None;
    let mut code = None;
    let start = Instant::now();
    for i in 0..a.frames {
        let camera = path.camera(i as f32 / (a.frames.max(2) - 1) as f32, w, h);
        let mut t = FrameTimings::default();
        let clock = Instant::now();
        let g = render_gbuffer(&ts, &camera);
        t.gbuffer_ms = clock.elapsed().as_secs_f64() * 1e3;
        let (k, rot) = schedule.at(i, a.frames);
        if last != Some((k, rot)) {
            // The encoder runs only when the lighting changes.
            let clock = Instant::now();
            code = Some(model.light_code(&schedule.maps[k], rot));
            t.encoder_ms = clock.elapsed().as_secs_f64() * 1e3;
            last = Some((k, rot));
        }
        let clock = Instant::now();
        let mut rgb = model.shade(&g, code.as_ref().expect("code computed on the first frame"));
        t.network_ms = clock.elapsed().as_secs_f64() * 1e3;
        let map = schedule.maps[k].rotated_y(rot);
        background(&camera, &map, &g.mask, &mut rgb);
        let png = frames_dir.join(format!("{i:04}.png"));
        write_png(&rgb, w as usize, h as usize, a.exposure, &png)?;
        if a.exr {
            let ch = (0..3)
                .map(|c| (["R", "G", "B"][c].to_string(), rgb.iter().map(|v| v[c]).collect()))
                .collect::<Vec<_>>();
            nprt_trace::exr_io::write_channels(&png.with_extension("exr"), w as usize, h as usize, &ch)?;
        }
        pngs.push(png);
        let eta = start.elapsed().as_secs_f64() / (i + 1) as f64 * (a.frames - i - 1) as f64;
        println!(
            "frame {:>4}/{}: G-buffer {:7.1} ms, encoder {:6.1} ms, network {:8.1} ms (ETA {eta:.0} s)",
            i + 1,
            a.frames,
            t.gbuffer_ms,
            t.encoder_ms,
            t.network_ms
        );
        csv += &format!(
            "{i},{},{rot:.3},{:.3},{:.3},{:.3},{:.3}\n",
            schedule.segments[k].map,
            t.gbuffer_ms,
            t.encoder_ms,
            t.network_ms,
            t.total_ms()
        );
        sum.gbuffer_ms += t.gbuffer_ms;
        sum.encoder_ms += t.encoder_ms;
        sum.network_ms += t.network_ms;
    }
    nprt_trace::exr_io::write_atomically(&a.out.join("timings.csv"), |tmp| Ok(std::fs::write(tmp, &csv)?))?;
    let anim = write_animation(&pngs, a.fps, &a.out.join("animation"))?;
    let n = a.frames as f64;
    println!(
        "mean per frame: G-buffer {:.1} ms, encoder {:.1} ms (once per lighting change), network {:.1} ms; total {:.1} ms ({:.2} fps)",
        sum.gbuffer_ms / n,
        sum.encoder_ms / n,
        sum.network_ms / n,
        sum.total_ms() / n,
        1e3 * n / sum.total_ms()
    );
    let kind = match anim {
        Animation::Mp4(_) => "MP4 (ffmpeg)",
        Animation::Gif(_) => "GIF (ffmpeg not on PATH or failed)",
    };
    println!("wrote {} frames to {}, animation {} [{kind}]", a.frames, frames_dir.display(), anim.path().display());
    Ok(())
}
