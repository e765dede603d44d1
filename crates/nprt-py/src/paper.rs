//! `nprt.paper`: `nprt paper` from Python, its sizes `nprt_paper::Budget`'s.

use std::path::PathBuf;

use nprt_data::CameraChoice;
use nprt_net::training::snapshot::Snapshot;
use nprt_paper::{Budget, Experiment};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays;
use crate::choice::engine;
use crate::error::OrPy;

/// Runs the paper's tables on `scene` under `envmaps` at `budget` ("tiny", "small", "medium",
/// "paper") into `out` (resuming what a run left there) and returns a dict: `paper_md`,
/// `paper_html` and `report_html` (paths), `results` (the evaluation's results.json) and
/// `orderings` (each ordering the paper states: table, statement, verdict). `snapshots`
/// (`"1m,2m,4m"`) keeps the four designs at points of their training and judges the orderings
/// at each (`nprt paper --snapshots`); `training_minutes` trains every network that long
/// instead of the budget's (`nprt paper --training-minutes`). The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (
    scene, envmaps, out, *, budget = "small", camera_volume = None, test_maps = None, seed = 0,
    device = "cpu", snapshots = None, training_minutes = None
))]
#[allow(clippy::too_many_arguments)]
pub fn paper<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    envmaps: &Bound<'py, PyAny>,
    out: PathBuf,
    budget: &str,
    camera_volume: Option<PathBuf>,
    test_maps: Option<usize>,
    seed: u64,
    device: &str,
    snapshots: Option<&str>,
    training_minutes: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let scene = crate::scene::scene_spec(scene, "scene")?;
    let envmaps = crate::scene::envmaps_spec(envmaps)?;
    let budget: Budget = budget
        .parse()
        .map_err(|e: anyhow::Error| crate::error::input_error(e.to_string()))?;
    let x = Experiment {
        camera: CameraChoice {
            file: camera_volume,
            ..CameraChoice::default()
        },
        test_maps,
        snapshots: (snapshots.map(Snapshot::parse_list).transpose())
            .map_err(|e| crate::error::input_error(format!("snapshots: {e}")))?
            .unwrap_or_default(),
        seed,
        training_minutes,
        ..Experiment::paper(&scene, &envmaps, &out, budget, engine(device)?)
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
