//! `nprt.evaluate`: `nprt eval` from Python, its defaults `EvalOptions::default()`'s.

use nprt_eval::{evaluate as run, write_report, EvalOptions};
use pyo3::prelude::*;

use crate::argument;
use crate::arrays;
use crate::choice::engine_arg;
use crate::interruptible::interruptible;

/// Evaluates `models` (a model folder, or a list of them) on the test views of the dataset
/// `data` beside every baseline, writes the report into `out` (report.md, report.html,
/// results.json, images/) and returns results.json as a dict. Keywords are `nprt eval`'s flags;
/// `None` takes its default: `deep_shading` (a Deep Shading model folder to compare),
/// `sh_spp`, `timing_res`, `views` (the first N test views), `shown_views`, `seed`,
/// `direct_spp`, `temporal_frames`, `temporal_res`, `nrc_warmup`, `oracles` (for a model that
/// traces its direct light, the rows that say where its error lives), `device` and `progress`.
/// The GIL is released while it runs; Ctrl-C stops it between its stages, before the report
/// is written (`nprt.Interrupted`).
#[pyfunction]
#[pyo3(signature = (
    data, models, out, *, deep_shading = None, sh_spp = None, timing_res = None, views = None,
    shown_views = None, seed = None, direct_spp = None, temporal_frames = None,
    temporal_res = None, nrc_warmup = None, oracles = None, device = None, progress = None
), text_signature = "(data, models, out, *, deep_shading=None, sh_spp=None, timing_res=None, \
    views=None, shown_views=None, seed=None, direct_spp=None, temporal_frames=None, \
    temporal_res=None, nrc_warmup=None, oracles=False, device='cpu', progress=True)")]
#[allow(clippy::too_many_arguments)]
pub fn evaluate<'py>(
    py: Python<'py>,
    data: &Bound<'py, PyAny>,
    models: &Bound<'py, PyAny>,
    out: &Bound<'py, PyAny>,
    deep_shading: Option<&Bound<'py, PyAny>>,
    sh_spp: Option<&Bound<'py, PyAny>>,
    timing_res: Option<&Bound<'py, PyAny>>,
    views: Option<&Bound<'py, PyAny>>,
    shown_views: Option<&Bound<'py, PyAny>>,
    seed: Option<&Bound<'py, PyAny>>,
    direct_spp: Option<&Bound<'py, PyAny>>,
    temporal_frames: Option<&Bound<'py, PyAny>>,
    temporal_res: Option<&Bound<'py, PyAny>>,
    nrc_warmup: Option<&Bound<'py, PyAny>>,
    oracles: Option<&Bound<'py, PyAny>>,
    device: Option<&Bound<'py, PyAny>>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    use argument::whole_or_none as whole;
    let d = EvalOptions::default();
    let out = argument::path(out, "out")?;
    let opts = EvalOptions {
        data: argument::path(data, "data")?,
        models: argument::paths(models, "models")?,
        deep_shading: argument::path_or_none(deep_shading, "deep_shading")?,
        sh_spp: whole(sh_spp, "sh_spp", 1..=u32::MAX)?.unwrap_or(d.sh_spp),
        timing_res: whole(timing_res, "timing_res", 1..=u32::MAX)?.unwrap_or(d.timing_res),
        max_views: whole(views, "views", 1..=usize::MAX)?.or(d.max_views),
        shown_views: whole(shown_views, "shown_views", 0..=usize::MAX)?.unwrap_or(d.shown_views),
        seed: whole(seed, "seed", 0..=u64::MAX)?.unwrap_or(d.seed),
        direct_spp: whole(direct_spp, "direct_spp", 0..=u32::MAX)?.unwrap_or(d.direct_spp),
        temporal_frames: whole(temporal_frames, "temporal_frames", 0..=usize::MAX)?
            .unwrap_or(d.temporal_frames),
        temporal_res: whole(temporal_res, "temporal_res", 1..=u32::MAX)?.unwrap_or(d.temporal_res),
        nrc_warmup: whole(nrc_warmup, "nrc_warmup", 0..=usize::MAX)?.unwrap_or(d.nrc_warmup),
        oracles: argument::flag_or(oracles, "oracles", d.oracles)?,
        progress: argument::flag_or(progress, "progress", true)?,
    };
    let engine = engine_arg(device)?;
    interruptible(py, || {
        let e = run(&opts, engine)?;
        write_report(&e, &out)
    })?;
    arrays::json_file(py, &out.join("results.json"))
}
