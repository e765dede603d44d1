//! `nprt.paper`: `nprt paper` from Python, its sizes `nprt_paper::Budget`'s.

use nprt_data::CameraChoice;
use nprt_net::training::snapshot::Snapshot;
use nprt_paper::{Budget, Experiment};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::argument;
use crate::arrays;
use crate::choice::{engine_arg, named_or};
use crate::error::OrPy;

/// Runs the paper's tables on `scene` under `envmaps` at `budget` ("tiny", "small", "medium",
/// "paper") into `out` (resuming what a run left there) and returns a dict: `paper_md`,
/// `paper_html` and `report_html` (paths), `results` (the evaluation's results.json) and
/// `orderings` (each ordering the paper states: table, statement, verdict). `snapshots`
/// (`"1m,2m,4m"`) keeps the four designs at points of their training and judges the orderings
/// at each (`nprt paper --snapshots`); `training_minutes` trains every network that long
/// instead of the budget's (`nprt paper --training-minutes`); `camera_volume`, `test_maps`,
/// `seed` and `device` are `nprt paper`'s flags of those names. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (
    scene, envmaps, out, *, budget = None, camera_volume = None, test_maps = None, seed = None,
    device = None, snapshots = None, training_minutes = None
), text_signature = "(scene, envmaps, out, *, budget='small', camera_volume=None, \
    test_maps=None, seed=0, device='cpu', snapshots=None, training_minutes=None)")]
#[allow(clippy::too_many_arguments)]
pub fn paper<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    envmaps: &Bound<'py, PyAny>,
    out: &Bound<'py, PyAny>,
    budget: Option<&Bound<'py, PyAny>>,
    camera_volume: Option<&Bound<'py, PyAny>>,
    test_maps: Option<&Bound<'py, PyAny>>,
    seed: Option<&Bound<'py, PyAny>>,
    device: Option<&Bound<'py, PyAny>>,
    snapshots: Option<&Bound<'py, PyAny>>,
    training_minutes: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let scene = crate::scene::scene_spec(scene, "scene")?;
    let envmaps = crate::scene::envmaps_spec(envmaps)?;
    let out = argument::path(out, "out")?;
    let budget: Budget = named_or(budget, "budget", "small")?;
    let snapshots = argument::text_or_none(snapshots, "snapshots", "a str such as \"1m,2m,4m\"")?;
    let range = nprt_net::MIN_MINUTES..=nprt_net::MAX_MINUTES;
    let x = Experiment {
        camera: CameraChoice {
            file: argument::path_or_none(camera_volume, "camera_volume")?,
            ..CameraChoice::default()
        },
        test_maps: argument::whole_or_none(test_maps, "test_maps", 1..=usize::MAX)?,
        snapshots: (snapshots.as_deref().map(Snapshot::parse_list).transpose())
            .map_err(|e| crate::error::input_error(format!("snapshots={snapshots:?}: {e}")))?
            .unwrap_or_default(),
        seed: argument::whole_or_none(seed, "seed", 0..=u64::MAX)?.unwrap_or(0),
        training_minutes: argument::number_or_none(training_minutes, "training_minutes", range)?,
        ..Experiment::paper(&scene, &envmaps, &out, budget, engine_arg(device)?)
    };
    let done = py.detach(|| x.run()).or_py()?;
    let d = PyDict::new(py);
    if let Some((md, html)) = &done.paper {
        d.set_item("paper_md", md)?;
        d.set_item("paper_html", html)?;
    }
    d.set_item("report_html", &done.report)?;
    d.set_item(
        "results",
        arrays::json_file(py, &out.join("report").join("results.json"))?,
    )?;
    let orderings: Vec<(&str, String, &str)> =
        nprt_paper::orderings::all(&done.evaluation, &done.ablation)
            .iter()
            .map(|o| (o.table, o.statement.clone(), o.verdict().word()))
            .collect();
    d.set_item("orderings", orderings)?;
    Ok(d)
}
