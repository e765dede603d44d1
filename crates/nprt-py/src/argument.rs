//! Arguments as Python passes them, checked by name before any work: text and files as a `str`
//! or an `os.PathLike` alike (one way to pass things; scenes and maps add their loaded objects,
//! `scene::scene_arg`), and floats that must be finite.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyString;

use crate::error::input_error;

/// `obj` as text: a `str`, or an `os.PathLike` (`pathlib.Path`) naming a file in UTF-8;
/// an InputError naming `arg` and what it takes (`takes`) otherwise.
pub fn text(obj: &Bound<'_, PyAny>, arg: &str, takes: &str) -> PyResult<String> {
    let refused = || {
        let kind = obj.get_type().name().map_or("?".into(), |n| n.to_string());
        input_error(format!("{arg} must be {takes}, not {kind}"))
    };
    let path = match obj.cast::<PyString>() {
        Ok(s) => s.clone(),
        Err(_) => {
            let fspath = obj.py().import("os")?.getattr("fspath")?;
            let p = fspath.call1((obj,)).map_err(|_| refused())?;
            p.cast_into::<PyString>().map_err(|_| {
                input_error(format!(
                    "{arg}: a path given as bytes; give a str or a pathlib.Path"
                ))
            })?
        }
    };
    path.extract::<String>()
        .map_err(|_| input_error(format!("{arg} is not valid UTF-8")))
}

/// A path argument: a `str` or an `os.PathLike`.
pub fn path(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<PathBuf> {
    text(obj, arg, "a str or an os.PathLike").map(PathBuf::from)
}

/// `value` where it is finite; an InputError naming `arg` otherwise (NaN would make NaN
/// frames, infinity runs without end).
pub fn finite<T: Copy + Into<f64> + std::fmt::Display>(value: T, arg: &str) -> PyResult<T> {
    if value.into().is_finite() {
        Ok(value)
    } else {
        Err(input_error(format!(
            "{arg} must be a finite number, not {value}"
        )))
    }
}

/// [`finite`] on an optional argument.
pub fn finite_or_none<T: Copy + Into<f64> + std::fmt::Display>(
    value: Option<T>,
    arg: &str,
) -> PyResult<Option<T>> {
    value.map(|v| finite(v, arg)).transpose()
}
