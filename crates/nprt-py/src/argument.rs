//! Arguments as Python passes them, checked by name before any conversion: the one layer that
//! refuses a bad value, as an `InputError` naming the keyword, the value and the rule (the
//! binding's own conversions raised TypeError or OverflowError naming neither). Text and files
//! as a `str` or an `os.PathLike` alike (scenes and maps add their loaded objects,
//! `scene::scene_arg`); whole numbers (Python's or numpy's, not a bool or a float) within a
//! range; numbers finite within a range; a size as one number or two; points as three numbers;
//! flags as `True`/`False`; callbacks callable.

use std::fmt::Display;
use std::ops::RangeInclusive;
use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat, PyString};

use crate::error::input_error;

/// `obj` as the message says it: its `repr`, cut to 60 characters.
fn said(obj: &Bound<'_, PyAny>) -> String {
    let text = obj.repr().map_or("?".into(), |r| r.to_string());
    match text.chars().count() > 60 {
        true => format!("{}…", text.chars().take(60).collect::<String>()),
        false => text,
    }
}

/// The InputError for `arg`'s value `obj`, which breaks `rule`: "spp=-1: must be …".
pub fn refused(obj: &Bound<'_, PyAny>, arg: &str, rule: impl Display) -> PyErr {
    input_error(format!("{arg}={}: {rule}", said(obj)))
}

/// A whole number within `range`: a Python or numpy integer (anything with `__index__`), not a
/// bool and not a float, even an integral one (as `range()` takes it).
pub fn whole<T>(obj: &Bound<'_, PyAny>, arg: &str, range: RangeInclusive<T>) -> PyResult<T>
where
    T: Copy + Display + TryFrom<i128>,
    i128: TryFrom<T>,
{
    let (lo, hi) = (*range.start(), *range.end());
    let rule = || format!("must be a whole number from {lo} to {hi}");
    if obj.is_instance_of::<PyBool>() || obj.is_instance_of::<PyFloat>() {
        return Err(refused(obj, arg, rule()));
    }
    let v: i128 = obj.extract().map_err(|_| refused(obj, arg, rule()))?;
    let inside =
        i128::try_from(lo).is_ok_and(|lo| v >= lo) && i128::try_from(hi).is_ok_and(|hi| v <= hi);
    match (inside, T::try_from(v)) {
        (true, Ok(v)) => Ok(v),
        _ => Err(refused(obj, arg, rule())),
    }
}

/// [`whole`] of an argument that may be `None` (its default).
pub fn whole_or_none<T>(
    obj: Option<&Bound<'_, PyAny>>,
    arg: &str,
    range: RangeInclusive<T>,
) -> PyResult<Option<T>>
where
    T: Copy + Display + TryFrom<i128>,
    i128: TryFrom<T>,
{
    obj.filter(|o| !o.is_none())
        .map(|o| whole(o, arg, range))
        .transpose()
}

/// A number (an int or a float, Python's or numpy's; not a bool, a complex or a str) that is
/// finite and within `range`.
pub fn number(obj: &Bound<'_, PyAny>, arg: &str, range: RangeInclusive<f64>) -> PyResult<f64> {
    let rule = || {
        format!(
            "must be a finite number from {} to {}",
            nprt_io::short_number(*range.start()),
            nprt_io::short_number(*range.end())
        )
    };
    if obj.is_instance_of::<PyBool>() {
        return Err(refused(obj, arg, rule()));
    }
    match obj.extract::<f64>() {
        Ok(v) if v.is_finite() && range.contains(&v) => Ok(v),
        _ => Err(refused(obj, arg, rule())),
    }
}

/// [`number`] of an argument that may be `None`.
pub fn number_or_none(
    obj: Option<&Bound<'_, PyAny>>,
    arg: &str,
    range: RangeInclusive<f64>,
) -> PyResult<Option<f64>> {
    obj.filter(|o| !o.is_none())
        .map(|o| number(o, arg, range))
        .transpose()
}

/// Any finite number.
pub const FINITE: RangeInclusive<f64> = f64::MIN..=f64::MAX;

/// The largest side of a frame or a view a size argument takes (the memory checks refuse what
/// does not fit long before).
const MAX_SIDE: u32 = 1 << 20;

/// A size in pixels: one number for a square (as the command line's `--train-res 64`) or
/// two, (width, height), each from 1 to 2²⁰.
pub fn size(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<(u32, u32)> {
    let rule = format!("must be a pixel count from 1 to {MAX_SIDE}, or two: (width, height)");
    if let Ok(n) = whole(obj, arg, 1..=MAX_SIDE) {
        return Ok((n, n));
    }
    whole_pair(obj, arg, 1..=MAX_SIDE, &rule)
}

/// Two whole numbers within `range` (a list, a tuple or an array of two); anything else is
/// `obj` refused as breaking `rule`.
fn whole_pair<T>(
    obj: &Bound<'_, PyAny>,
    arg: &str,
    range: RangeInclusive<T>,
    rule: &str,
) -> PyResult<(T, T)>
where
    T: Copy + Display + TryFrom<i128>,
    i128: TryFrom<T>,
{
    let items = sequence(obj)
        .filter(|v| v.len() == 2)
        .ok_or_else(|| refused(obj, arg, rule))?;
    let one =
        |o: &Bound<'_, PyAny>| whole(o, arg, range.clone()).map_err(|_| refused(obj, arg, rule));
    Ok((one(&items[0])?, one(&items[1])?))
}

/// [`size`] of an argument that may be `None`.
pub fn size_or_none(obj: Option<&Bound<'_, PyAny>>, arg: &str) -> PyResult<Option<(u32, u32)>> {
    obj.filter(|o| !o.is_none())
        .map(|o| size(o, arg))
        .transpose()
}

/// The items of a list, tuple or array (not of a str or bytes, which iterate too).
fn sequence<'py>(obj: &Bound<'py, PyAny>) -> Option<Vec<Bound<'py, PyAny>>> {
    if obj.is_instance_of::<PyString>() || obj.is_instance_of::<pyo3::types::PyBytes>() {
        return None;
    }
    obj.try_iter().ok()?.collect::<PyResult<Vec<_>>>().ok()
}

/// A point or direction: three finite numbers (a list, a tuple or an array of shape (3,)).
pub fn vec3(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<[f32; 3]> {
    let rule = "must be three finite numbers (x, y, z)";
    let items = sequence(obj)
        .filter(|v| v.len() == 3)
        .ok_or_else(|| refused(obj, arg, rule))?;
    let mut v = [0.0f32; 3];
    for (out, item) in v.iter_mut().zip(&items) {
        *out = number(item, arg, FINITE).map_err(|_| refused(obj, arg, rule))? as f32;
    }
    Ok(v)
}

/// [`vec3`] of an argument that may be `None`.
pub fn vec3_or_none(obj: Option<&Bound<'_, PyAny>>, arg: &str) -> PyResult<Option<[f32; 3]>> {
    obj.filter(|o| !o.is_none())
        .map(|o| vec3(o, arg))
        .transpose()
}

/// A shard `(k, n)`: the k-th of n, 0 ≤ k < n.
pub fn shard(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<(u64, u64)> {
    let rule = "must be (k, n), two whole numbers with 0 <= k < n";
    match whole_pair(obj, arg, 0..=u64::MAX, rule)? {
        (k, n) if k < n => Ok((k, n)),
        _ => Err(refused(obj, arg, rule)),
    }
}

/// A flag: `True` or `False` (numpy's too), not a number or a str that Python would call true.
pub fn flag(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<bool> {
    let numpy_bool = obj
        .get_type()
        .name()
        .is_ok_and(|n| n == "bool" || n == "bool_");
    match numpy_bool {
        true => obj.is_truthy(),
        false => Err(refused(obj, arg, "must be True or False")),
    }
}

/// [`flag`] of an argument that may be `None` (then `default`).
pub fn flag_or(obj: Option<&Bound<'_, PyAny>>, arg: &str, default: bool) -> PyResult<bool> {
    obj.filter(|o| !o.is_none())
        .map_or(Ok(default), |o| flag(o, arg))
}

/// A callback: callable, or `None`; checked before any work (one that is not was found only
/// after an epoch had trained and a model folder was written).
pub fn callable_or_none(obj: Option<Bound<'_, PyAny>>, arg: &str) -> PyResult<Option<Py<PyAny>>> {
    match obj.filter(|o| !o.is_none()) {
        Some(o) if !o.is_callable() => Err(refused(&o, arg, "must be callable (or None)")),
        o => Ok(o.map(Bound::unbind)),
    }
}

/// [`text`] of an argument that may be `None`.
pub fn text_or_none(
    obj: Option<&Bound<'_, PyAny>>,
    arg: &str,
    takes: &str,
) -> PyResult<Option<String>> {
    obj.filter(|o| !o.is_none())
        .map(|o| text(o, arg, takes))
        .transpose()
}

/// One path or a list of them (a `str` or an `os.PathLike` each).
pub fn paths(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<Vec<PathBuf>> {
    if let Ok(one) = path(obj, arg) {
        return Ok(vec![one]);
    }
    let items = sequence(obj)
        .filter(|v| !v.is_empty())
        .ok_or_else(|| refused(obj, arg, "must be a path or a non-empty list of paths"))?;
    items.iter().map(|p| path(p, arg)).collect()
}

/// [`path`] of an argument that may be `None`.
pub fn path_or_none(obj: Option<&Bound<'_, PyAny>>, arg: &str) -> PyResult<Option<PathBuf>> {
    obj.filter(|o| !o.is_none())
        .map(|o| path(o, arg))
        .transpose()
}

/// `obj` as text: a `str`, or an `os.PathLike` (`pathlib.Path`) naming a file in UTF-8;
/// an InputError naming `arg` and what it takes (`takes`) otherwise.
pub fn text(obj: &Bound<'_, PyAny>, arg: &str, takes: &str) -> PyResult<String> {
    let refused = || {
        let kind = obj.get_type().name().map_or("?".into(), |n| n.to_string());
        input_error(format!("{arg}={}: must be {takes}, not {kind}", said(obj)))
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

/// numpy's kinds of real numbers (signed, unsigned, floating point); with "b", bools too.
pub const REAL: &str = "iuf";

/// `obj` as numpy holds it (`numpy.asarray`: nested lists become an array; nothing is copied),
/// and its shape; refused naming `arg` (as `shape_rule` of real numbers) where its values are
/// not of numpy's `kinds`: complex values (whose imaginary part a float conversion drops), text
/// or objects, and bools unless `kinds` has "b".
pub fn real_array<'py>(
    obj: &Bound<'py, PyAny>,
    arg: &str,
    shape_rule: &str,
    kinds: &str,
) -> PyResult<(Bound<'py, PyAny>, Vec<usize>)> {
    let array = (obj.py().import("numpy")?)
        .call_method1("asarray", (obj,))
        .map_err(|_| refused(obj, arg, format!("must be {shape_rule} of real numbers")))?;
    let kind: String = array.getattr("dtype")?.getattr("kind")?.extract()?;
    if !kinds.contains(kind.as_str()) {
        let what = match kind.as_str() {
            "c" => "complex numbers",
            "b" => "bools",
            _ => "values that are not numbers",
        };
        return Err(refused(
            obj,
            arg,
            format!("must be {shape_rule} of real numbers, not of {what}"),
        ));
    }
    let shape = array.getattr("shape")?.extract()?;
    Ok((array, shape))
}

/// An (H, W, 3) array of real numbers ([`real_array`]), and its (H, W); refused naming `arg`
/// when it is not. Nothing is copied: a broadcast view of a huge shape costs nothing until its
/// size is checked.
pub fn rgb_array<'py>(
    obj: &Bound<'py, PyAny>,
    arg: &str,
    shape_rule: &str,
) -> PyResult<(Bound<'py, PyAny>, usize, usize)> {
    let (array, shape) = real_array(obj, arg, shape_rule, REAL)?;
    match shape.as_slice() {
        &[h, w, 3] => Ok((array, h, w)),
        _ => Err(refused(
            obj,
            arg,
            format!("must be {shape_rule}, not of shape {shape:?}"),
        )),
    }
}

/// The texels of an array [`rgb_array`] accepted, as float32 RGB row by row.
pub fn rgb_texels(array: &Bound<'_, PyAny>, arg: &str) -> PyResult<Vec<glam::Vec3>> {
    let texels: numpy::PyArrayLike3<f32, numpy::AllowTypeChange> = array
        .extract()
        .map_err(|e| input_error(format!("{arg}: not an array of numbers ({e})")))?;
    let texels = texels.as_array();
    Ok(texels
        .rows()
        .into_iter()
        .map(|p| glam::Vec3::new(p[0], p[1], p[2]))
        .collect())
}
