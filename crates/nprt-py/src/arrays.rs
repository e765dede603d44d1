//! numpy arrays in and out: images as (H, W, 3) float32, cameras as 4 × 4 camera-to-world
//! matrices (Mitsuba's convention: columns left, up, forward, origin) with a horizontal field
//! of view, and JSON values as Python objects.

use glam::{Mat4, Vec3};
use nprt_scene::{Camera, FovAxis};
use numpy::{IntoPyArray, PyArray2, PyArray3};
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

/// Per pixel, `k` coefficients of each colour channel (pixel-major, then coefficient, then
/// channel) as an (H, W, K, 3) float32 array.
pub fn coefficients<'py>(
    py: Python<'py>,
    values: &[f32],
    width: usize,
    height: usize,
    k: usize,
) -> Bound<'py, numpy::PyArray4<f32>> {
    numpy::ndarray::Array4::from_shape_vec((height, width, k, 3), values.to_vec())
        .expect("K × 3 values a pixel")
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

/// `width` × `height` as a frame's size, each a pixel count (named where it is not).
pub fn frame_size(width: &Bound<'_, PyAny>, height: &Bound<'_, PyAny>) -> PyResult<(u32, u32)> {
    let side = |v, arg| crate::argument::whole(v, arg, 1..=u32::MAX);
    Ok((side(width, "width")?, side(height, "height")?))
}

/// A camera from `camera`, a 4 × 4 camera-to-world matrix (rows first: a numpy array or nested
/// lists), a horizontal field of view `fov` (degrees, `None`: 60) and a resolution; an
/// InputError naming the argument and what is wrong (shape, entries that are not finite
/// numbers, a frame that is not a rotation and a translation, sizes).
pub fn camera(
    camera: &Bound<'_, PyAny>,
    fov: Option<&Bound<'_, PyAny>>,
    width: u32,
    height: u32,
) -> PyResult<Camera> {
    use crate::argument::refused;
    let rows = matrix4(camera)?;
    let fov_deg = crate::argument::number_or_none(fov, "fov", 0.0..=180.0)?.unwrap_or(60.0);
    if !(fov_deg > 0.0 && fov_deg < 180.0) {
        return Err(refused(
            fov.expect("a given fov"),
            "fov",
            "must be between 0 and 180 degrees (exclusive)",
        ));
    }
    let to_world = Mat4::from_cols_array_2d(&rows).transpose();
    let axes = [
        to_world.x_axis.truncate(),
        to_world.y_axis.truncate(),
        to_world.z_axis.truncate(),
    ];
    if axes.iter().any(|a| (a.length() - 1.0).abs() > 1e-3) || rows[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err(refused(
            camera,
            "camera",
            "must rotate and translate only (unit axes, last row 0 0 0 1)",
        ));
    }
    nprt_trace::Frame::check_size(width, height, "the frame")
        .map_err(|e| crate::error::input_error(format!("width={width}, height={height}: {e:#}")))?;
    Ok(Camera {
        to_world,
        fov_deg: fov_deg as f32,
        fov_axis: FovAxis::X,
        width,
        height,
    })
}

/// `obj` as a 4 × 4 matrix of finite numbers, rows first.
fn matrix4(obj: &Bound<'_, PyAny>) -> PyResult<[[f32; 4]; 4]> {
    use crate::argument::{real_array, refused, REAL};
    let rule = "must be a 4 × 4 camera-to-world matrix of finite numbers";
    let (array, shape) = real_array(obj, "camera", "a 4 × 4 camera-to-world matrix", REAL)?;
    if shape != [4, 4] {
        return Err(refused(
            obj,
            "camera",
            format!("{rule}, not of shape {shape:?}"),
        ));
    }
    let values: Vec<Vec<f64>> = array
        .call_method1("astype", ("float64",))?
        .call_method0("tolist")?
        .extract()?;
    let mut rows = [[0.0f32; 4]; 4];
    for (i, row) in values.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            if !v.is_finite() {
                return Err(refused(
                    obj,
                    "camera",
                    format!("{rule}: entry ({i}, {j}) is {v}"),
                ));
            }
            rows[i][j] = v as f32;
        }
    }
    Ok(rows)
}

/// A G-buffer from a dict of the dataset's channels (`position`, `normal`, `view`, `kd`, `ks`:
/// (H, W, 3); `alpha`, `mask`: (H, W)), all of one size; and that size (W, H). Each refused
/// naming its key.
pub fn gbuffer(obj: &Bound<'_, PyAny>) -> PyResult<(nprt_trace::GBuffer, usize, usize)> {
    use crate::argument::refused;
    let rule = "must be a dict of G-buffer channels (a Dataset view is one)";
    if !obj.is_instance_of::<pyo3::types::PyDict>() {
        return Err(refused(obj, "gbuffer", rule));
    }
    let item = |key: &str| {
        obj.get_item(key)
            .map_err(|_| refused(obj, "gbuffer", format!("{rule}: it has no '{key}'")))
    };
    let mut size = None;
    let mut same = |key: &str, h: usize, w: usize| match size.replace((h, w)) {
        Some(s) if s != (h, w) => Err(crate::error::input_error(format!(
            "gbuffer['{key}'] is {h} × {w} pixels, the channels before it {} × {}",
            s.0, s.1
        ))),
        _ => Ok(()),
    };
    let mut rgb = |key: &str| -> PyResult<Vec<Vec3>> {
        let arg = format!("gbuffer['{key}']");
        let (array, h, w) = crate::argument::rgb_array(&item(key)?, &arg, "an (H, W, 3) array")?;
        same(key, h, w)?;
        crate::argument::rgb_texels(&array, &arg)
    };
    let (position, normal, view, kd, ks) = (
        rgb("position")?,
        rgb("normal")?,
        rgb("view")?,
        rgb("kd")?,
        rgb("ks")?,
    );
    let mut plane = |key: &str| -> PyResult<Vec<f32>> {
        let arg = format!("gbuffer['{key}']");
        let value = item(key)?;
        // A mask of bools (`view["mask"] > 0`) is one too.
        let (array, shape) = crate::argument::real_array(&value, &arg, "an (H, W) array", "biuf")?;
        let &[h, w] = shape.as_slice() else {
            return Err(refused(
                &value,
                &arg,
                format!("must be an (H, W) array, not of shape {shape:?}"),
            ));
        };
        same(key, h, w)?;
        array
            .call_method1("astype", ("float32",))?
            .call_method0("ravel")?
            .call_method0("tolist")?
            .extract()
    };
    let (alpha, mask) = (plane("alpha")?, plane("mask")?);
    let (h, w) = size.expect("channels were read");
    let g = nprt_trace::GBuffer {
        position,
        normal,
        view,
        kd,
        ks,
        alpha,
        mask,
    };
    if let Some(i) = (0..w * h).find(|&i| {
        let v = [g.position[i], g.normal[i], g.view[i], g.kd[i], g.ks[i]];
        !(v.iter().all(|c| c.is_finite()) && g.alpha[i].is_finite() && g.mask[i].is_finite())
    }) {
        return Err(crate::error::input_error(format!(
            "gbuffer: pixel ({}, {}) holds a value that is not finite",
            i % w,
            i / w
        )));
    }
    Ok((g, w, h))
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
