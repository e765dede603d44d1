//! `nprt.bake`: `nprt bake` from Python, its sizes `nprt_paper::bake::Quality`'s.

use std::path::PathBuf;

use nprt_data::CameraChoice;
use nprt_eval::MethodResult;
use nprt_paper::bake::{Bake, Quality};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::argument::finite_or_none;
use crate::choice::engine;
use crate::interruptible::interruptible;

/// Bakes `scene` under `envmaps` (a folder of maps, or "builtin") into a relit model in `out`
/// at `quality` ("draft", "good" or "best"; "tiny" for tests), as `nprt bake`: the dataset,
/// the recommended recipe trained (`minutes`, or `epochs` for a run reproducible bit for bit),
/// and a check against path tracing of equal cost on held-out views; a run already in `out` is
/// resumed. Returns a dict: `model`, `comparison`, `preview` and `report` (paths),
/// `description` (the model as run time runs it), `views` (held-out views checked),
/// `held_out_maps`, `model_errors` and `path_tracing_errors` (each `name`, `l1`, `rmse`,
/// `dssim`, `ms_per_view`, `level`: per channel, 1 is the reference's), `denoised` (whether its
/// traced light measured better denoised, which run time then follows; None without OIDN) and
/// `seconds`. The GIL is
/// released while it runs; Ctrl-C stops it at the next view or epoch (`nprt.Interrupted`), and
/// the same call resumes it.
#[pyfunction]
#[pyo3(signature = (
    scene, envmaps, out, *, quality = "draft", minutes = None, epochs = None,
    camera_volume = None, test_maps = None, seed = 0, device = "cpu", progress = true
))]
#[allow(clippy::too_many_arguments)]
pub fn bake<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    envmaps: &Bound<'py, PyAny>,
    out: PathBuf,
    quality: &str,
    minutes: Option<f64>,
    epochs: Option<usize>,
    camera_volume: Option<PathBuf>,
    test_maps: Option<usize>,
    seed: u64,
    device: &str,
    progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let scene = crate::scene::scene_spec(scene, "scene")?;
    let envmaps = crate::scene::envmaps_spec(envmaps)?;
    let quality: Quality = quality
        .parse()
        .map_err(|e: anyhow::Error| crate::error::input_error(format!("quality: {e}")))?;
    let bake = Bake {
        minutes: finite_or_none(minutes, "minutes")?,
        epochs,
        camera: CameraChoice {
            file: camera_volume,
            ..CameraChoice::default()
        },
        test_maps,
        seed,
        progress,
        ..Bake::new(&scene, &envmaps, &out, quality, engine(device)?)
    };
    let b = interruptible(py, || bake.run())?;
    let d = PyDict::new(py);
    d.set_item("model", &b.model)?;
    d.set_item("comparison", &b.comparison)?;
    d.set_item("preview", &b.preview)?;
    d.set_item("report", &b.report)?;
    d.set_item("description", &b.description)?;
    d.set_item("views", b.views)?;
    d.set_item("held_out_maps", &b.held_out_maps)?;
    d.set_item("model_errors", errors(py, &b.model_row)?)?;
    match &b.path_tracing {
        Some(pt) => d.set_item("path_tracing_errors", errors(py, pt)?)?,
        None => d.set_item("path_tracing_errors", py.None())?,
    }
    d.set_item("denoised", b.check.as_ref().map(|c| c.denoise))?;
    d.set_item("seconds", b.seconds)?;
    Ok(d)
}

/// A row of the check as a dict.
fn errors<'py>(py: Python<'py>, m: &MethodResult) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", &m.name)?;
    d.set_item("l1", m.mean.l1)?;
    d.set_item("rmse", m.mean.rmse)?;
    d.set_item("dssim", m.mean.dssim)?;
    d.set_item("ms_per_view", m.ms_per_view)?;
    d.set_item("level", m.level.to_vec())?;
    Ok(d)
}
