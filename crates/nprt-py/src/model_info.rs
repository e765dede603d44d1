//! `nprt.model_info`: `nprt model info` from Python, a design's or a trained model's layer
//! table and parameter counts as a dict (nprt-net's `ModelSummary`).

use nprt_net::{ModelSummary, DEFAULT_ENCODER_WIDTH};
use pyo3::prelude::*;

use crate::argument;
use crate::choice::named;
use crate::error::OrPy;

/// The layer table and parameter counts of the trained model in `model`, or of the design
/// `arch` (untrained, with `activation`, `encoder_width` and `encoding` as `nprt model info`
/// takes them): a dict with `config`, `layers` (name, shape, params), `encoder_params`,
/// `transport_params` (without hash-grid entries, as the paper's Table 1), `paper_params`,
/// `grid_entries` and `total_params`; for a model also `dataset_hash`, `scene_hash` and
/// `level_gain`.
#[pyfunction]
#[pyo3(signature = (model = None, *, arch = None, activation = None, encoder_width = None, encoding = None))]
pub fn model_info<'py>(
    py: Python<'py>,
    model: Option<&Bound<'py, PyAny>>,
    arch: Option<&Bound<'py, PyAny>>,
    activation: Option<&Bound<'py, PyAny>>,
    encoder_width: Option<&Bound<'py, PyAny>>,
    encoding: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let model = argument::path_or_none(model, "model")?;
    let arch: Option<nprt_net::Design> = named(arch, "arch")?;
    let activation = named(activation, "activation")?;
    let encoding = named(encoding, "encoding")?;
    let encoder_width = argument::whole_or_none(encoder_width, "encoder_width", 1..=usize::MAX)?;
    let (summary, file) = match (model, arch) {
        (Some(dir), None) => {
            let (file, summary) = py.detach(|| ModelSummary::of_model(&dir)).or_py()?;
            (summary, Some(file))
        }
        (None, Some(arch)) => {
            let summary = ModelSummary::of_design(
                arch,
                activation,
                encoder_width.unwrap_or(DEFAULT_ENCODER_WIDTH),
                encoding.unwrap_or_default(),
            )
            .or_py()?;
            (summary, None)
        }
        (Some(_), Some(_)) => {
            return Err(crate::error::input_error(
                "give a model folder or arch=, not both",
            ))
        }
        (None, None) => {
            return Err(crate::error::input_error(
                "give a model folder (model=) or a design (arch=)",
            ))
        }
    };
    let mut value = serde_json::to_value(&summary)
        .map_err(anyhow::Error::from)
        .or_py()?;
    if let Some(f) = file {
        value["dataset_hash"] = f.dataset_hash.into();
        value["scene_hash"] = f.scene_hash.into();
        value["level_gain"] = serde_json::to_value(f.level_gain)
            .map_err(anyhow::Error::from)
            .or_py()?;
    }
    py.import("json")?
        .call_method1("loads", (value.to_string(),))
}
