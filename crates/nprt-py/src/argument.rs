//! Arguments as Python passes them, checked by name before any work: a scene, a map or a file
//! as a `str`, an `os.PathLike` or the loaded object alike (one way to pass things), and
//! floats that must be finite.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyString;

use crate::error::input_error;
use crate::scene::{self, EnvMap, Scene};

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
                input_error(format!("{arg}: a path given as bytes; give a str or a pathlib.Path"))
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

const SCENE: &str = "an nprt.Scene, a str or an os.PathLike (a scene file or builtin:room)";
const MAP: &str =
    "an nprt.EnvMap, a str or an os.PathLike (an .exr/.hdr file or a builtin: map)";

/// The scene `obj` is or names (`builtin:room`, a file), loaded where it is named.
pub fn scene<'py>(obj: &Bound<'py, PyAny>, arg: &str) -> PyResult<Bound<'py, Scene>> {
    if let Ok(s) = obj.cast::<Scene>() {
        return Ok(s.clone());
    }
    let spec = text(obj, arg, SCENE)?;
    Bound::new(obj.py(), scene::load(obj.py(), &spec)?)
}

/// What `obj` names as a scene, to hand a command: a loaded scene's own spec.
pub fn scene_spec(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<String> {
    match obj.cast::<Scene>() {
        Ok(s) => Ok(s.get().spec.clone()),
        Err(_) => text(obj, arg, SCENE),
    }
}

/// The map `obj` is or names, opened where it is named.
pub fn envmap<'py>(obj: &Bound<'py, PyAny>, arg: &str) -> PyResult<Bound<'py, EnvMap>> {
    if let Ok(m) = obj.cast::<EnvMap>() {
        return Ok(m.clone());
    }
    let spec = text(obj, arg, MAP)?;
    Bound::new(obj.py(), scene::open(obj.py(), &spec)?)
}

/// `value` where it is finite; an InputError naming `arg` otherwise (NaN would make NaN
/// frames, infinity runs without end).
pub fn finite<T: Copy + Into<f64> + std::fmt::Display>(value: T, arg: &str) -> PyResult<T> {
    if value.into().is_finite() {
        Ok(value)
    } else {
        Err(input_error(format!("{arg} must be a finite number, not {value}")))
    }
}

/// [`finite`] on an optional argument.
pub fn finite_or_none<T: Copy + Into<f64> + std::fmt::Display>(
    value: Option<T>,
    arg: &str,
) -> PyResult<Option<T>> {
    value.map(|v| finite(v, arg)).transpose()
}
