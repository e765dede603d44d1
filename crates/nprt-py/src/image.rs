//! Images to and from files, as numpy arrays: `nprt.write_image` and `nprt.read_image` (the
//! library's one writer and one reader of linear RGB).

use numpy::PyArray3;
use pyo3::prelude::*;

use crate::argument;
use crate::arrays;
use crate::error::OrPy;

/// Writes `image`, an (H, W, 3) array of linear radiance, to `path` (a `str` or a
/// `pathlib.Path`) in the format its extension names: .exr (float32, exact), .hdr (Radiance)
/// or .png (8-bit sRGB of the radiance scaled by 2**`exposure`). Written whole or not at all;
/// NaN or infinity is refused, naming the pixel.
#[pyfunction]
#[pyo3(signature = (path, image, exposure = None), text_signature = "(path, image, exposure=0.0)")]
pub fn write_image(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    image: &Bound<'_, PyAny>,
    exposure: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let path = argument::path(path, "path")?;
    let exposure =
        argument::number_or_none(exposure, "exposure", argument::FINITE)?.unwrap_or(0.0) as f32;
    let (array, h, w) = argument::rgb_array(image, "image", "an (H, W, 3) array")?;
    let rgb = argument::rgb_texels(&array, "image")?;
    py.detach(|| nprt_io::write_linear_rgb(&path, &rgb, w, h, exposure))
        .or_py()
}

/// Reads the image at `path` (.exr, .hdr, .png, .jpg; a `str` or a `pathlib.Path`) as an
/// (H, W, 3) float32 array of linear RGB: 8-bit formats through the sRGB curve, float formats
/// as they are.
#[pyfunction]
pub fn read_image<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let path = argument::path(path, "path")?;
    let img = py
        .detach(|| nprt_io::read_linear_rgb(&path, false))
        .or_py()?;
    Ok(arrays::image(py, &img.texels, img.width, img.height))
}
