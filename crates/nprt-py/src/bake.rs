//! `nprt.bake`: `nprt bake` from Python, its sizes `nprt_paper::bake::Quality`'s.

use nprt_data::CameraChoice;
use nprt_eval::MethodResult;
use nprt_paper::bake::{Bake, Quality};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::argument;
use crate::choice::{engine_arg, named_or};
use crate::interruptible::interruptible;

/// Bakes `scene` under `envmaps` (a folder of maps, or "builtin") into a relit model in `out`
/// at `quality` ("draft", "good" or "best"; "tiny" for tests), as `nprt bake`: the dataset,
/// the recommended recipe trained (`minutes`, or `epochs` for a run reproducible bit for bit),
/// and a check against path tracing of equal cost on held-out views; a run already in `out` is
/// resumed. `camera_volume` is a camera-volume file for a scene without one, `test_maps` the
/// maps held out of training, `seed` the dataset's, `device` and `progress` as for `train`. Returns a dict: `model`, `comparison`, `preview` and `report` (paths),
/// `description` (the model as run time runs it), `views` (held-out views checked),
/// `held_out_maps`, `model_errors` and `path_tracing_errors` (each `name`, `l1`, `rmse`,
/// `dssim`, `ms_per_view`, `level`: per channel, 1 is the reference's), `denoised` (whether its
/// traced light measured better denoised, which run time then follows; None without OIDN) and
/// `seconds`. The GIL is
/// released while it runs; Ctrl-C stops it at the next view or epoch (`nprt.Interrupted`), and
/// the same call resumes it.
#[pyfunction]
#[pyo3(signature = (
    scene, envmaps, out, *, quality = None, minutes = None, epochs = None,
    camera_volume = None, test_maps = None, seed = None, device = None, progress = None
), text_signature = "(scene, envmaps, out, *, quality='draft', minutes=None, epochs=None, \
    camera_volume=None, test_maps=None, seed=0, device='cpu', progress=True)")]
#[allow(clippy::too_many_arguments)]
pub fn bake<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    envmaps: &Bound<'py, PyAny>,
    out: &Bound<'py, PyAny>,
    quality: Option<&Bound<'py, PyAny>>,
    minutes: Option<&Bound<'py, PyAny>>,
    epochs: Option<&Bound<'py, PyAny>>,
    camera_volume: Option<&Bound<'py, PyAny>>,
    test_maps: Option<&Bound<'py, PyAny>>,
    seed: Option<&Bound<'py, PyAny>>,
    device: Option<&Bound<'py, PyAny>>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let scene = crate::scene::scene_spec(scene, "scene")?;
    let envmaps = crate::scene::envmaps_spec(envmaps)?;
    let out = argument::path(out, "out")?;
    let quality: Quality = named_or(quality, "quality", "draft")?;
    let range = nprt_net::MIN_MINUTES..=nprt_net::MAX_MINUTES;
    let bake = Bake {
        minutes: argument::number_or_none(minutes, "minutes", range)?,
        epochs: argument::whole_or_none(epochs, "epochs", 1..=usize::MAX)?,
        camera: CameraChoice {
            file: argument::path_or_none(camera_volume, "camera_volume")?,
            ..CameraChoice::default()
        },
        test_maps: argument::whole_or_none(test_maps, "test_maps", 1..=usize::MAX)?,
        seed: argument::whole_or_none(seed, "seed", 0..=u64::MAX)?.unwrap_or(0),
        progress: argument::flag_or(progress, "progress", true)?,
        ..Bake::new(&scene, &envmaps, &out, quality, engine_arg(device)?)
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
