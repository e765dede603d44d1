//! `nprt.export`: `nprt export` from Python, its defaults `ExampleView::default()`'s.

use std::path::PathBuf;

use nprt_render::ExampleView;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::argument;
use crate::error::OrPy;

/// Writes the model in `model` as shaders and weights for engines into `out` (the kernels as
/// WGSL, GLSL and HLSL, weights.bin, export.json, and a WebGPU page relighting a view of
/// `example_res` (width, height, or one number for a square) under `example_map`, a map file
/// or a `builtin:` map), as `nprt export`; returns the files
/// written, the weights and, where the page could not be made, why.
#[pyfunction]
#[pyo3(signature = (model, out, *, example_res = None, example_map = None))]
pub fn export<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    out: &Bound<'py, PyAny>,
    example_res: Option<&Bound<'py, PyAny>>,
    example_map: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (model, out) = (argument::path(model, "model")?, argument::path(out, "out")?);
    let d = ExampleView::default();
    let (width, height) =
        argument::size_or_none(example_res, "example_res")?.unwrap_or((d.width, d.height));
    let view = ExampleView {
        width,
        height,
        map: argument::text_or_none(example_map, "example_map", "a str or an os.PathLike")?
            .unwrap_or(d.map),
    };
    let done = py.detach(|| written(&model, &out, &view)).or_py()?;
    let summary = PyDict::new(py);
    summary.set_item("files", done.0)?;
    summary.set_item("weights", done.1)?;
    summary.set_item("no_example", done.2)?;
    Ok(summary)
}

type Written = (Vec<PathBuf>, usize, Option<String>);

#[cfg(feature = "gpu")]
fn written(
    model: &std::path::Path,
    out: &std::path::Path,
    view: &ExampleView,
) -> anyhow::Result<Written> {
    let done = nprt_render::gpu::export_model(model, out, view)?;
    Ok((done.files, done.weights, done.no_example))
}

#[cfg(not(feature = "gpu"))]
fn written(_: &std::path::Path, _: &std::path::Path, _: &ExampleView) -> anyhow::Result<Written> {
    anyhow::bail!("this nprt was built without its GPU kernels, which export writes: build the wheel with the `gpu` feature (python/pyproject.toml does)")
}
