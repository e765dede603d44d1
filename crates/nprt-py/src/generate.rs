//! `nprt.generate`: `nprt generate` from Python, every flag a keyword whose default is
//! `GenerateOptions::default()`'s.

use nprt_data::dataset::{Jitter, Summary, TransferBasis};
use nprt_data::{CameraChoice, GenerateOptions, ViewSpec};
use nprt_net::RECIPE;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::argument;
use crate::choice;
use crate::interruptible::interruptible;

/// Renders a dataset of `scene` (a loaded `nprt.Scene`, or a file or `builtin:room` as a `str`
/// or a `pathlib.Path`) under `envmaps` (a folder of maps, or "builtin") into `out` (resumed
/// where one with the same settings is there) and
/// returns what was rendered: `rendered`, `skipped` (already complete), `seconds`,
/// `msamples_per_s` and `warnings`. Keywords are `nprt generate`'s flags; `None` takes its
/// default (`nprt generate --help`): `train_views` and `test_views` (views of each split),
/// `train_res` and `test_res` (their size: one number for a square, or (width, height)), `spp`
/// and `test_spp` (paths per pixel of each), `seed`, `jitter_exposure` and `jitter_tint` (each
/// view's random gain on its map), `test_maps` (maps held out for the test views),
/// `mix_builtin` (the share of training views lit by built-in maps), `mix_maps` (maps added to
/// each training view's), `shard` ((k, n): the k-th of n parts), the camera volume as a
/// `camera_volume` file or `volume_min`, `volume_max` and `look` (three numbers each) with
/// `spread` and `fov` (degrees), `transfer` ("sh:L" records transfer vectors to band L,
/// "none" none) and `progress` (a bar on stderr). `device` traces on "cpu" or the GPU ("gpu", "wgpu",
/// "auto"). The GIL is released while it renders; Ctrl-C stops it after the view under way
/// (`nprt.Interrupted`), and the same call resumes it.
#[pyfunction]
#[pyo3(signature = (
    scene, envmaps, out, *, train_views = None, test_views = None, train_res = None,
    test_res = None, spp = None, test_spp = None, seed = None, jitter_exposure = None,
    jitter_tint = None, test_maps = None, mix_builtin = None, shard = None, camera_volume = None,
    volume_min = None, volume_max = None, look = None, spread = None, fov = None,
    device = None, progress = None, mix_maps = None, transfer = None
), text_signature = "(scene, envmaps, out, *, train_views=None, test_views=None, train_res=None, \
    test_res=None, spp=None, test_spp=None, seed=None, jitter_exposure=None, jitter_tint=None, \
    test_maps=None, mix_builtin=None, shard=None, camera_volume=None, volume_min=None, \
    volume_max=None, look=None, spread=None, fov=None, device='cpu', progress=True, \
    mix_maps=None, transfer=None)")]
#[allow(clippy::too_many_arguments)]
pub fn generate<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    envmaps: &Bound<'py, PyAny>,
    out: &Bound<'py, PyAny>,
    train_views: Option<&Bound<'py, PyAny>>,
    test_views: Option<&Bound<'py, PyAny>>,
    train_res: Option<&Bound<'py, PyAny>>,
    test_res: Option<&Bound<'py, PyAny>>,
    spp: Option<&Bound<'py, PyAny>>,
    test_spp: Option<&Bound<'py, PyAny>>,
    seed: Option<&Bound<'py, PyAny>>,
    jitter_exposure: Option<&Bound<'py, PyAny>>,
    jitter_tint: Option<&Bound<'py, PyAny>>,
    test_maps: Option<&Bound<'py, PyAny>>,
    mix_builtin: Option<&Bound<'py, PyAny>>,
    shard: Option<&Bound<'py, PyAny>>,
    camera_volume: Option<&Bound<'py, PyAny>>,
    volume_min: Option<&Bound<'py, PyAny>>,
    volume_max: Option<&Bound<'py, PyAny>>,
    look: Option<&Bound<'py, PyAny>>,
    spread: Option<&Bound<'py, PyAny>>,
    fov: Option<&Bound<'py, PyAny>>,
    device: Option<&Bound<'py, PyAny>>,
    progress: Option<&Bound<'py, PyAny>>,
    mix_maps: Option<&Bound<'py, PyAny>>,
    transfer: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    use argument::{number_or_none as num, size_or_none, vec3_or_none, whole_or_none as whole};
    let d = GenerateOptions::default();
    let v = d.views;
    let device = choice::engine_arg(device)?.tracer();
    let f32_of = |v: Option<f64>| v.map(|v| v as f32);
    let opts = GenerateOptions {
        scene: crate::scene::scene_spec(scene, "scene")?,
        envmaps: crate::scene::envmaps_spec(envmaps)?,
        out: argument::path(out, "out")?,
        views: ViewSpec {
            train_views: whole(train_views, "train_views", 1..=u64::MAX)?.unwrap_or(v.train_views),
            test_views: whole(test_views, "test_views", 1..=u64::MAX)?.unwrap_or(v.test_views),
            train_resolution: size_or_none(train_res, "train_res")?
                .map_or(v.train_resolution, |(w, h)| [w, h]),
            test_resolution: size_or_none(test_res, "test_res")?
                .map_or(v.test_resolution, |(w, h)| [w, h]),
            spp: whole(spp, "spp", 1..=u32::MAX)?.unwrap_or(v.spp),
            test_spp: whole(test_spp, "test_spp", 1..=u32::MAX)?.unwrap_or(v.test_spp),
            seed: whole(seed, "seed", 0..=u64::MAX)?.unwrap_or(v.seed),
            jitter: jitter([jitter_exposure, jitter_tint], v.jitter)?,
            mix_maps: whole(mix_maps, "mix_maps", 0..=u32::MAX)?.unwrap_or(v.mix_maps),
        },
        transfer: match argument::text_or_none(transfer, "transfer", "a str: sh:L or none")? {
            Some(t) => TransferBasis::parse_choice(&t)
                .map_err(|e| crate::error::input_error(format!("transfer={t:?}: {e:#}")))?,
            None => RECIPE.dataset_transfer_on(device),
        },
        test_maps: whole(test_maps, "test_maps", 1..=usize::MAX)?.or(d.test_maps),
        mix_builtin: f32_of(num(mix_builtin, "mix_builtin", 0.0..=1.0)?).or(d.mix_builtin),
        camera: CameraChoice {
            file: argument::path_or_none(camera_volume, "camera_volume")?,
            min: vec3_or_none(volume_min, "volume_min")?.map(Into::into),
            max: vec3_or_none(volume_max, "volume_max")?.map(Into::into),
            look: vec3_or_none(look, "look")?.map(Into::into),
            spread_deg: f32_of(num(spread, "spread", 0.0..=90.0)?),
            fov_deg: f32_of(num(fov, "fov", 0.0..=180.0)?),
        },
        shard: match shard.filter(|s| !s.is_none()) {
            Some(s) => argument::shard(s, "shard")?,
            None => d.shard,
        },
        device,
        progress: argument::flag_or(progress, "progress", true)?,
    };
    let mut warnings = Vec::new();
    let summary = interruptible(py, || nprt_data::generate(&opts, |p| warnings = p.warnings))?;
    summary_dict(py, summary, warnings)
}

/// What `generate` returns: the views rendered, skipped and redone, the time, the rate and the
/// plan's warnings.
fn summary_dict<'py>(
    py: Python<'py>,
    summary: Summary,
    warnings: Vec<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("rendered", summary.rendered)?;
    out.set_item("skipped", summary.skipped)?;
    out.set_item("redone", summary.redone)?;
    out.set_item("seconds", summary.seconds)?;
    out.set_item(
        "msamples_per_s",
        summary.samples / summary.seconds.max(1e-9) / 1e6,
    )?;
    out.set_item("warnings", warnings)?;
    Ok(out)
}

/// The jitter of each view's map from `jitter_exposure` and `jitter_tint`, each `default`'s
/// where None.
fn jitter([exposure, tint]: [Option<&Bound<'_, PyAny>>; 2], default: Jitter) -> PyResult<Jitter> {
    let of = |v: Option<&Bound<'_, PyAny>>, arg: &str, default: f32| -> PyResult<f32> {
        let v = argument::number_or_none(v, arg, 0.0..=f64::MAX)?;
        Ok(v.map_or(default, |v| v as f32))
    };
    Ok(Jitter {
        exposure: of(exposure, "jitter_exposure", default.exposure)?,
        tint: of(tint, "jitter_tint", default.tint)?,
    })
}
