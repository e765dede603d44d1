//! `nprt.render`: `nprt render` from Python (a camera path relit under a lighting schedule,
//! written as frames and an animation), its defaults `RenderOptions::default()`'s.

use std::path::PathBuf;

use nprt_render::{Denoise, RenderJob, RenderOptions};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::argument::finite_or_none;
use crate::choice::{engine, parse};
use crate::interruptible::interruptible;

/// Relights a camera path of the model in `model` under a lighting schedule into `out` (PNG
/// frames, or EXR with `exr`, and an MP4 or GIF), as `nprt render`; keywords are its flags,
/// `None` its default. Returns `description` (what runs, in one line), `frames_dir`,
/// `animation` and the mean per-frame milliseconds (`gbuffer_ms`, `encoder_ms`, `network_ms`,
/// `direct_ms`, `total_ms`). The GIL is released
/// while it renders; Ctrl-C stops it after the frame under way (`nprt.Interrupted`).
#[pyfunction]
#[pyo3(signature = (
    model, out, *, scene = None, camera_path = None, camera_volume = None, lighting = None,
    spin = None, frames = None, res = None, fps = None, exposure = None, exr = false,
    direct_spp = None, denoise_direct = None, precision = None, device = "cpu"
))]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    model: PathBuf,
    out: PathBuf,
    scene: Option<&Bound<'py, PyAny>>,
    camera_path: Option<PathBuf>,
    camera_volume: Option<PathBuf>,
    lighting: Option<String>,
    spin: Option<f32>,
    frames: Option<usize>,
    res: Option<(u32, u32)>,
    fps: Option<u32>,
    exposure: Option<f32>,
    exr: bool,
    direct_spp: Option<u32>,
    denoise_direct: Option<&Bound<'py, PyAny>>,
    precision: Option<&str>,
    device: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let d = RenderOptions::default();
    let opts = RenderOptions {
        model,
        out,
        scene: scene
            .map(|s| crate::scene::scene_spec(s, "scene"))
            .transpose()?,
        camera_path,
        camera_volume,
        lighting: lighting.unwrap_or(d.lighting),
        spin_deg: finite_or_none(spin, "spin")?.unwrap_or(d.spin_deg),
        frames: frames.unwrap_or(d.frames),
        resolution: res.map_or(d.resolution, |(w, h)| [w, h]),
        fps: fps.unwrap_or(d.fps),
        exposure: finite_or_none(exposure, "exposure")?.unwrap_or(d.exposure),
        exr,
        direct_spp: direct_spp.unwrap_or(d.direct_spp),
        denoise_direct: denoise_choice(denoise_direct)?.unwrap_or(d.denoise_direct),
        precision: precision.map(parse).transpose()?.unwrap_or(d.precision),
    };
    let engine = engine(device)?;
    let (done, description) = interruptible(py, || {
        let job = RenderJob::prepare(&opts, engine)?;
        Ok((job.run(|_| {})?, job.describe()))
    })?;
    let m = done.mean;
    let summary = PyDict::new(py);
    summary.set_item("description", description)?;
    summary.set_item("frames_dir", done.frames_dir)?;
    summary.set_item("animation", done.animation.path().to_path_buf())?;
    summary.set_item("gbuffer_ms", m.gbuffer_ms)?;
    summary.set_item("encoder_ms", m.encoder_ms)?;
    summary.set_item("network_ms", m.network_ms)?;
    summary.set_item("direct_ms", m.direct_ms)?;
    summary.set_item("total_ms", m.total_ms())?;
    Ok(summary)
}

/// `denoise_direct`: True ("on"), False ("off") or one of "auto", "on", "off"; None takes the
/// default (auto: OIDN where installed).
pub fn denoise_choice(value: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Denoise>> {
    let Some(v) = value else {
        return Ok(None);
    };
    if let Ok(on) = v.extract::<bool>() {
        return Ok(Some(if on { Denoise::On } else { Denoise::Off }));
    }
    match v.extract::<String>() {
        Ok(name) => parse(&name).map(Some),
        Err(_) => Err(crate::error::input_error(format!(
            "denoise_direct: expected True, False, 'auto', 'on' or 'off', not {}",
            v.get_type().name()?
        ))),
    }
}
