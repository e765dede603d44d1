//! `nprt.render`: `nprt render` from Python (a camera path relit under a lighting schedule,
//! written as frames and an animation), its defaults `RenderOptions::default()`'s.

use nprt_render::{Denoise, RenderJob, RenderOptions, SequenceSummary};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::argument;
use crate::choice::{engine_arg, named};
use crate::interruptible::interruptible;

/// Relights a camera path of the model in `model` under a lighting schedule into `out` (PNG
/// frames, or EXR with `exr`, and an MP4 or GIF), as `nprt render`, or with `out=None` into
/// memory (the frames come back as an (N, H, W, 3) float32 array of linear radiance, `frames`,
/// and no file is left); keywords are its flags,
/// `None` its default: `scene` (another scene than the model's), the path as a `camera_path`
/// file or orbiting a `camera_volume` (`spin` degrees over the path), `lighting` (a map or a
/// lighting schedule), `frames`, `res` ((width, height) or one number), `fps`, `exposure`
/// (stops), `direct_spp` and `denoise_direct` (a traced direct light's paths per pixel and
/// denoising: True, False, "auto", "on" or "off"), `precision` ("f32" or "f16") and `device`. Returns `description` (what runs, in one line), `frames_dir`,
/// `animation` and the mean per-frame milliseconds (`gbuffer_ms`, `encoder_ms`, `network_ms`,
/// `direct_ms`, `total_ms`). The GIL is released
/// while it renders; Ctrl-C stops it after the frame under way (`nprt.Interrupted`).
#[pyfunction]
#[pyo3(signature = (
    model, out = None, *, scene = None, camera_path = None, camera_volume = None, lighting = None,
    spin = None, frames = None, res = None, fps = None, exposure = None, exr = None,
    direct_spp = None, denoise_direct = None, precision = None, device = None
), text_signature = "(model, out=None, *, scene=None, camera_path=None, camera_volume=None, \
    lighting=None, spin=None, frames=None, res=None, fps=None, exposure=None, exr=False, \
    direct_spp=None, denoise_direct=None, precision=None, device='cpu')")]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    out: Option<&Bound<'py, PyAny>>,
    scene: Option<&Bound<'py, PyAny>>,
    camera_path: Option<&Bound<'py, PyAny>>,
    camera_volume: Option<&Bound<'py, PyAny>>,
    lighting: Option<&Bound<'py, PyAny>>,
    spin: Option<&Bound<'py, PyAny>>,
    frames: Option<&Bound<'py, PyAny>>,
    res: Option<&Bound<'py, PyAny>>,
    fps: Option<&Bound<'py, PyAny>>,
    exposure: Option<&Bound<'py, PyAny>>,
    exr: Option<&Bound<'py, PyAny>>,
    direct_spp: Option<&Bound<'py, PyAny>>,
    denoise_direct: Option<&Bound<'py, PyAny>>,
    precision: Option<&Bound<'py, PyAny>>,
    device: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    use argument::{number_or_none as num, whole_or_none as whole};
    let d = RenderOptions::default();
    let out = argument::path_or_none(out, "out")?;
    // In memory: frames written as EXR into a folder of the call's own, read back, removed.
    let scratch = out.is_none().then(|| {
        static CALLS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let n = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        std::env::temp_dir().join(format!("nprt-render-{}-{n}", std::process::id()))
    });
    let opts = RenderOptions {
        model: argument::path(model, "model")?,
        out: out.clone().or(scratch.clone()).expect("an output folder"),
        scene: scene
            .filter(|s| !s.is_none())
            .map(|s| crate::scene::scene_spec(s, "scene"))
            .transpose()?,
        camera_path: argument::path_or_none(camera_path, "camera_path")?,
        camera_volume: argument::path_or_none(camera_volume, "camera_volume")?,
        lighting: argument::text_or_none(lighting, "lighting", "a str or an os.PathLike")?
            .unwrap_or(d.lighting),
        spin_deg: num(spin, "spin", argument::FINITE)?.map_or(d.spin_deg, |v| v as f32),
        frames: whole(frames, "frames", 1..=usize::MAX)?.unwrap_or(d.frames),
        resolution: argument::size_or_none(res, "res")?.map_or(d.resolution, |(w, h)| [w, h]),
        fps: whole(fps, "fps", 1..=1000)?.unwrap_or(d.fps),
        exposure: num(exposure, "exposure", argument::FINITE)?.map_or(d.exposure, |v| v as f32),
        exr: argument::flag_or(exr, "exr", false)? || scratch.is_some(),
        direct_spp: whole(direct_spp, "direct_spp", 0..=u32::MAX)?.unwrap_or(d.direct_spp),
        denoise_direct: denoise_choice(denoise_direct)?.unwrap_or(d.denoise_direct),
        precision: named(precision, "precision")?.unwrap_or(d.precision),
    };
    let engine = engine_arg(device)?;
    let rendered = interruptible(py, || {
        let job = RenderJob::prepare(&opts, engine)?;
        let done = job.run(|_| {})?;
        let frames = match &scratch {
            Some(_) => Some(read_frames(&done.frames_dir, opts.frames)?),
            None => None,
        };
        Ok((done, job.describe(), frames))
    });
    if let Some(dir) = &scratch {
        let _ = std::fs::remove_dir_all(dir);
    }
    let (done, description, frames) = rendered?;
    summary_dict(py, done, description, frames)
}

/// What `render` returns: the description, the frames (as an array, or where they were
/// written) and the mean per-frame times.
fn summary_dict(
    py: Python<'_>,
    done: SequenceSummary,
    description: String,
    frames: Option<(Vec<f32>, usize, usize)>,
) -> PyResult<Bound<'_, PyDict>> {
    let m = done.mean;
    let summary = PyDict::new(py);
    summary.set_item("description", description)?;
    match frames {
        Some((rgb, w, h)) => {
            let n = rgb.len() / (3 * w * h).max(1);
            let array = numpy::ndarray::Array4::from_shape_vec((n, h, w, 3), rgb)
                .expect("frames of one size");
            summary.set_item("frames", numpy::IntoPyArray::into_pyarray(array, py))?;
        }
        None => {
            summary.set_item("frames_dir", done.frames_dir)?;
            summary.set_item("animation", done.animation.path().to_path_buf())?;
        }
    }
    summary.set_item("gbuffer_ms", m.gbuffer_ms)?;
    summary.set_item("encoder_ms", m.encoder_ms)?;
    summary.set_item("network_ms", m.network_ms)?;
    summary.set_item("direct_ms", m.direct_ms)?;
    summary.set_item("total_ms", m.total_ms())?;
    Ok(summary)
}

/// The `count` EXR frames in `dir` (NNNN.exr), their RGB in one buffer, and their size.
fn read_frames(dir: &std::path::Path, count: usize) -> anyhow::Result<(Vec<f32>, usize, usize)> {
    let mut rgb = Vec::new();
    let mut size = (0, 0);
    for i in 0..count {
        let frame = nprt_io::read_linear_rgb(&dir.join(format!("{i:04}.exr")), false)?;
        size = (frame.width, frame.height);
        rgb.extend(frame.texels.iter().flat_map(|t| t.to_array()));
    }
    Ok((rgb, size.0, size.1))
}

/// `denoise_direct`: True ("on"), False ("off") or one of "auto", "on", "off"; None takes the
/// default (auto: OIDN where installed).
pub fn denoise_choice(value: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Denoise>> {
    let Some(v) = value.filter(|v| !v.is_none()) else {
        return Ok(None);
    };
    if let Ok(on) = argument::flag(v, "denoise_direct") {
        return Ok(Some(if on { Denoise::On } else { Denoise::Off }));
    }
    match v.extract::<String>() {
        Ok(_) => named(Some(v), "denoise_direct"),
        Err(_) => Err(argument::refused(
            v,
            "denoise_direct",
            "must be True, False, 'auto', 'on' or 'off'",
        )),
    }
}
