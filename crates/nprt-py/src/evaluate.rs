//! `nprt.evaluate`: `nprt eval` from Python, its defaults `EvalOptions::default()`'s.

use std::path::PathBuf;

use nprt_eval::{evaluate as run, write_report, EvalOptions};
use pyo3::prelude::*;

use crate::arrays;
use crate::choice::engine;
use crate::interruptible::interruptible;

/// Evaluates `models` (model folders) on the test views of the dataset `data` beside every
/// baseline, writes the report into `out` (report.md, report.html, results.json, images/) and
/// returns results.json as a dict. Keywords are `nprt eval`'s flags; `None` takes its default.
/// The GIL is released while it runs; Ctrl-C stops it between its stages, before the report
/// is written (`nprt.Interrupted`).
#[pyfunction]
#[pyo3(signature = (
    data, models, out, *, deep_shading = None, sh_spp = None, timing_res = None, views = None,
    shown_views = None, seed = None, direct_spp = None, temporal_frames = None,
    temporal_res = None, nrc_warmup = None, device = "cpu", progress = true
))]
#[allow(clippy::too_many_arguments)]
pub fn evaluate<'py>(
    py: Python<'py>,
    data: PathBuf,
    models: Vec<PathBuf>,
    out: PathBuf,
    deep_shading: Option<PathBuf>,
    sh_spp: Option<u32>,
    timing_res: Option<u32>,
    views: Option<usize>,
    shown_views: Option<usize>,
    seed: Option<u64>,
    direct_spp: Option<u32>,
    temporal_frames: Option<usize>,
    temporal_res: Option<u32>,
    nrc_warmup: Option<usize>,
    device: &str,
    progress: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let d = EvalOptions::default();
    let opts = EvalOptions {
        data,
        models,
        deep_shading,
        sh_spp: sh_spp.unwrap_or(d.sh_spp),
        timing_res: timing_res.unwrap_or(d.timing_res),
        max_views: views.or(d.max_views),
        shown_views: shown_views.unwrap_or(d.shown_views),
        seed: seed.unwrap_or(d.seed),
        direct_spp: direct_spp.unwrap_or(d.direct_spp),
        temporal_frames: temporal_frames.unwrap_or(d.temporal_frames),
        temporal_res: temporal_res.unwrap_or(d.temporal_res),
        nrc_warmup: nrc_warmup.unwrap_or(d.nrc_warmup),
        progress,
        ..d
    };
    let engine = engine(device)?;
    interruptible(py, || {
        let e = run(&opts, engine)?;
        write_report(&e, &out)
    })?;
    arrays::json_file(py, &out.join("results.json"))
}
