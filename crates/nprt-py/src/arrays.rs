//! numpy arrays in and out: images as (H, W, 3) float32, cameras as 4 × 4 camera-to-world
//! matrices (Mitsuba's convention: columns left, up, forward, origin) with a horizontal field
//! of view, and JSON values as Python objects.

use anyhow::{bail, Result};
use glam::{Mat4, Vec3};
use nprt_scene::{Camera, FovAxis};
use numpy::{AllowTypeChange, IntoPyArray, PyArray2, PyArray3, PyArrayLike2};
use pyo3::prelude::*;

/// `rgb` (`width × height` pixels, row by row) as an (H, W, 3) float32 array.
pub fn image<'py>(
    py: Python<'py>,
    rgb: &[Vec3],
    width: usize,
    height: usize,
) -> Bound<'py, PyArray3<f32>> {
    let flat: Vec<f32> = rgb.iter().flat_map(|c| c.to_array()).collect();
    numpy::ndarray::Array3::from_shape_vec((height, width, 3), flat)
        .expect("an image of width × height pixels")
        .into_pyarray(py)
}

/// One value per pixel as an (H, W) float32 array.
pub fn plane<'py>(
    py: Python<'py>,
    values: &[f32],
    width: usize,
    height: usize,
) -> Bound<'py, PyArray2<f32>> {
    numpy::ndarray::Array2::from_shape_vec((height, width), values.to_vec())
        .expect("a plane of width × height pixels")
        .into_pyarray(py)
}

/// A camera as Python gets it: (4 × 4 camera-to-world matrix, horizontal field of view in
/// degrees, (width, height)).
pub type CameraOut<'py> = (Bound<'py, PyArray2<f64>>, f32, (u32, u32));

/// `m` as a 4 × 4 float64 array, rows first.
pub fn matrix<'py>(py: Python<'py>, m: Mat4) -> Bound<'py, PyArray2<f64>> {
    let rows = m.transpose().to_cols_array_2d();
    let flat: Vec<f64> = rows.iter().flatten().map(|&v| v as f64).collect();
    numpy::ndarray::Array2::from_shape_vec((4, 4), flat)
        .expect("4 × 4")
        .into_pyarray(py)
}

/// `width` × `height` as a frame's size, each named where it is not a positive pixel count
/// (Python's integers have no bound; a negative one would otherwise be an OverflowError that
/// names no argument).
pub fn frame_size(width: i64, height: i64) -> PyResult<(u32, u32)> {
    let side = |v: i64, arg: &str| {
        u32::try_from(v).ok().filter(|&v| v > 0).ok_or_else(|| {
            crate::error::input_error(format!(
                "{arg} must be a pixel count from 1 to {}, got {v}",
                u32::MAX
            ))
        })
    };
    Ok((side(width, "width")?, side(height, "height")?))
}

/// A camera from a 4 × 4 camera-to-world matrix (rows first), a horizontal field of view and
/// a resolution; an error naming what is wrong (shape, non-finite entries, a frame that is not
/// a rotation and a translation, sizes).
pub fn camera(
    to_world: PyArrayLike2<f32, AllowTypeChange>,
    fov_deg: f32,
    width: u32,
    height: u32,
) -> Result<Camera> {
    let m = to_world.as_array();
    if m.shape() != [4, 4] {
        bail!(
            "a camera is a 4 × 4 camera-to-world matrix, got shape {:?}",
            m.shape()
        );
    }
    let mut rows = [[0.0f32; 4]; 4];
    for ((i, j), &v) in m.indexed_iter() {
        if !v.is_finite() {
            bail!("the camera matrix holds a non-finite entry at ({i}, {j})");
        }
        rows[i][j] = v;
    }
    let to_world = Mat4::from_cols_array_2d(&rows).transpose();
    let axes = [
        to_world.x_axis.truncate(),
        to_world.y_axis.truncate(),
        to_world.z_axis.truncate(),
    ];
    if axes.iter().any(|a| (a.length() - 1.0).abs() > 1e-3) || rows[3] != [0.0, 0.0, 0.0, 1.0] {
        bail!("the camera matrix must rotate and translate only (unit axes, last row 0 0 0 1)");
    }
    if !(fov_deg > 0.0 && fov_deg < 180.0) {
        bail!("the field of view must be between 0 and 180 degrees, got {fov_deg}");
    }
    if width == 0 || height == 0 {
        bail!("a frame needs at least one pixel, got {width}×{height}");
    }
    nprt_trace::Frame::check_size(width, height, "the frame")?;
    Ok(Camera {
        to_world,
        fov_deg,
        fov_axis: FovAxis::X,
        width,
        height,
    })
}

/// A JSON value as the Python object `json.loads` makes of it.
pub fn json<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).expect("JSON values serialise");
    py.import("json")?.call_method1("loads", (text,))
}

/// The JSON file `path` (a model's model.json, a report's results.json) as a Python object;
/// an NprtError naming the file where it cannot be read.
pub fn json_file<'py>(py: Python<'py>, path: &std::path::Path) -> PyResult<Bound<'py, PyAny>> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        crate::error::NprtError::new_err(format!("cannot read '{}': {e}", path.display()))
    })?;
    py.import("json")?.call_method1("loads", (text,))
}
