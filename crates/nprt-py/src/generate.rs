//! `nprt.generate`: `nprt generate` from Python, every flag a keyword whose default is
//! `GenerateOptions::default()`'s.

use std::path::PathBuf;

use nprt_data::dataset::{Jitter, TransferBasis};
use nprt_data::{CameraChoice, GenerateOptions};
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
/// default (`nprt generate --help`). `device` traces on "cpu" or the GPU ("gpu", "wgpu",
/// "auto"). The GIL is released while it renders; Ctrl-C stops it after the view under way
/// (`nprt.Interrupted`), and the same call resumes it.
#[pyfunction]
#[pyo3(signature = (
    scene, envmaps, out, *, train_views = None, test_views = None, train_res = None,
    test_res = None, spp = None, test_spp = None, seed = None, jitter_exposure = None,
    jitter_tint = None, test_maps = None, mix_builtin = None, shard = None, camera_volume = None,
    volume_min = None, volume_max = None, look = None, spread = None, fov = None,
    device = "cpu", progress = true, mix_maps = None, transfer = None
))]
#[allow(clippy::too_many_arguments)]
pub fn generate<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    envmaps: &Bound<'py, PyAny>,
    out: PathBuf,
    train_views: Option<u64>,
    test_views: Option<u64>,
    train_res: Option<(u32, u32)>,
    test_res: Option<(u32, u32)>,
    spp: Option<u32>,
    test_spp: Option<u32>,
    seed: Option<u64>,
    jitter_exposure: Option<f32>,
    jitter_tint: Option<f32>,
    test_maps: Option<usize>,
    mix_builtin: Option<f32>,
    shard: Option<(u64, u64)>,
    camera_volume: Option<PathBuf>,
    volume_min: Option<[f32; 3]>,
    volume_max: Option<[f32; 3]>,
    look: Option<[f32; 3]>,
    spread: Option<f32>,
    fov: Option<f32>,
    device: &str,
    progress: bool,
    mix_maps: Option<u32>,
    transfer: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let (fin, fin3) = (argument::finite_or_none, finite_vec3);
    let d = GenerateOptions::default();
    let device = choice::engine(device)?.tracer();
    let opts = GenerateOptions {
        scene: crate::scene::scene_spec(scene, "scene")?,
        envmaps: crate::scene::envmaps_spec(envmaps)?,
        out,
        train_views: train_views.unwrap_or(d.train_views),
        test_views: test_views.unwrap_or(d.test_views),
        train_resolution: train_res.map_or(d.train_resolution, |(w, h)| [w, h]),
        test_resolution: test_res.map_or(d.test_resolution, |(w, h)| [w, h]),
        spp: spp.unwrap_or(d.spp),
        test_spp: test_spp.unwrap_or(d.test_spp),
        seed: seed.unwrap_or(d.seed),
        jitter: Jitter {
            exposure: fin(jitter_exposure, "jitter_exposure")?.unwrap_or(d.jitter.exposure),
            tint: fin(jitter_tint, "jitter_tint")?.unwrap_or(d.jitter.tint),
        },
        mix_maps: mix_maps.unwrap_or(d.mix_maps),
        transfer: match transfer {
            Some(t) => TransferBasis::parse_choice(t)
                .map_err(|e| crate::error::input_error(format!("transfer: {e:#}")))?,
            None => RECIPE.dataset_transfer_on(device),
        },
        test_maps: test_maps.or(d.test_maps),
        mix_builtin: fin(mix_builtin, "mix_builtin")?.or(d.mix_builtin),
        camera: CameraChoice {
            file: camera_volume,
            min: fin3(volume_min, "volume_min")?,
            max: fin3(volume_max, "volume_max")?,
            look: fin3(look, "look")?,
            spread_deg: fin(spread, "spread")?,
            fov_deg: fin(fov, "fov")?,
        },
        shard: shard.unwrap_or(d.shard),
        device,
        progress,
    };
    let mut warnings = Vec::new();
    let summary = interruptible(py, || nprt_data::generate(&opts, |p| warnings = p.warnings))?;
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

/// An optional point or direction, each coordinate finite (named `arg` otherwise).
fn finite_vec3(v: Option<[f32; 3]>, arg: &str) -> PyResult<Option<glam::Vec3>> {
    match v {
        Some(v) if !v.iter().all(|c| c.is_finite()) => Err(crate::error::input_error(format!(
            "{arg} must be three finite numbers, got {v:?}"
        ))),
        v => Ok(v.map(Into::into)),
    }
}
