//! A relit sequence: a camera path under a lighting schedule, rendered frame by frame with a
//! trained model and written as PNG (and optionally EXR) frames, an animation and timings.csv.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use glam::Vec3;
use nprt_trace::TraceScene;
use serde::Serialize;

use crate::oidn::Oidn;
use nprt_io::write_png;

use crate::{
    write_animation, Animation, CameraPath, DirectSampling, FrameCache, FrameTimings,
    LightingSchedule, Relighter,
};

/// What to render and where.
pub struct Sequence<'a> {
    pub path: &'a CameraPath,
    pub lighting: &'a LightingSchedule,
    pub frames: usize,
    pub resolution: [u32; 2],
    /// Frames per second of the animation.
    pub fps: u32,
    /// Exposure of the PNG frames and animation, in stops.
    pub exposure: f32,
    /// Samples per pixel of the direct light, for a model that traces it.
    pub direct_spp: u32,
    /// Denoises that light before adding it.
    pub denoiser: Option<&'static Oidn>,
    /// Also write each frame's linear radiance as OpenEXR.
    pub exr: bool,
    /// Output folder: frames/NNNN.png (.exr), animation.mp4 or .gif, timings.csv.
    pub out: &'a Path,
}

/// One finished frame, as reported to the caller while the sequence runs.
pub struct FrameReport {
    pub index: usize,
    pub timings: FrameTimings,
    /// Seconds the rest of the sequence should take at the rate so far.
    pub eta_s: f64,
}

/// What a finished sequence wrote and how long its frames took.
pub struct SequenceSummary {
    pub frames_dir: PathBuf,
    pub animation: Animation,
    /// Per-frame means; the encoder's share counts only frames where the lighting changed.
    pub mean: FrameTimings,
}

/// One row of timings.csv.
#[derive(Serialize)]
struct TimingRow<'a> {
    frame: usize,
    map: &'a str,
    rotation_deg: f32,
    gbuffer_ms: f64,
    encoder_ms: f64,
    network_ms: f64,
    direct_ms: f64,
    total_ms: f64,
}

/// Renders `seq` with `model` on `scene` (already checked to be the model's scene): the
/// G-buffer from primary rays, the encoder only when the lighting changes, the network on
/// foreground pixels, then the traced direct light (models that leave it to the tracer) or the
/// map as background. While the camera stands still, the G-buffer and
/// the transfer networks' outputs are kept and only the shading networks run again. Calls
/// `on_frame` after each frame.
pub fn render_sequence(
    model: &Relighter,
    scene: &TraceScene,
    seq: &Sequence,
    mut on_frame: impl FnMut(&FrameReport),
) -> Result<SequenceSummary> {
    if seq.frames == 0 || seq.fps == 0 {
        bail!("a sequence needs at least one frame and one frame per second");
    }
    let frames_dir = seq.out.join("frames");
    nprt_io::check_writable(&frames_dir.join("x"))?;
    let [w, h] = seq.resolution;
    let mut csv = csv::Writer::from_writer(Vec::new());
    let mut pngs = Vec::new();
    let mut sum = FrameTimings::default();
    let mut cache = FrameCache::default();
    let start = Instant::now();
    for i in 0..seq.frames {
        nprt_io::interrupt::check()?;
        let camera = seq
            .path
            .camera(i as f32 / (seq.frames.max(2) - 1) as f32, w, h);
        let (k, rot) = seq.lighting.at(i, seq.frames);
        let sampling = DirectSampling {
            spp: seq.direct_spp,
            seed: i as u64,
            denoiser: seq.denoiser,
        };
        let map = &seq.lighting.maps[k];
        let (rgb, t) = model.frame(&mut cache, scene, &camera, map, rot, (k, rot), sampling)?;
        let png = frames_dir.join(format!("{i:04}.png"));
        write_frame(&rgb, [w as usize, h as usize], seq, &png)?;
        pngs.push(png);
        csv.serialize(TimingRow {
            frame: i,
            map: &seq.lighting.segments[k].map,
            rotation_deg: rot,
            gbuffer_ms: t.gbuffer_ms,
            encoder_ms: t.encoder_ms,
            network_ms: t.network_ms,
            direct_ms: t.direct_ms,
            total_ms: t.total_ms(),
        })?;
        sum.add(&t);
        let eta_s = start.elapsed().as_secs_f64() / (i + 1) as f64 * (seq.frames - i - 1) as f64;
        on_frame(&FrameReport {
            index: i,
            timings: t,
            eta_s,
        });
    }
    let csv = csv.into_inner().context("cannot finish timings.csv")?;
    nprt_io::write_file(&seq.out.join("timings.csv"), csv)?;
    let animation = write_animation(&pngs, seq.fps, &seq.out.join("animation"))?;
    Ok(SequenceSummary {
        frames_dir,
        animation,
        mean: sum.scaled(1.0 / seq.frames as f64),
    })
}

/// A frame's radiance as a tone-mapped PNG at `png`, and as linear OpenEXR beside it when the
/// sequence asks for it.
fn write_frame(rgb: &[Vec3], [w, h]: [usize; 2], seq: &Sequence, png: &Path) -> Result<()> {
    write_png(rgb, w, h, seq.exposure, png)?;
    if seq.exr {
        let ch = ["R", "G", "B"]
            .iter()
            .enumerate()
            .map(|(c, name)| (name.to_string(), rgb.iter().map(|v| v[c]).collect()))
            .collect::<Vec<_>>();
        nprt_io::exr::write_channels(&png.with_extension("exr"), w, h, &ch)?;
    }
    Ok(())
}
