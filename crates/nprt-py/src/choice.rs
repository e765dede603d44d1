//! Named choices from Python strings, as the command line takes them: `device="gpu"`,
//! `arch="dsep"`, `precision="f16"`, … (each accepted name stated once, in nprt-net).

use std::str::FromStr;

use nprt_net::{Compute, Engine};
use pyo3::prelude::*;

use crate::error::OrPy;

/// `name` as a `T`; an InputError (a ValueError) listing the accepted names otherwise.
pub fn parse<T: FromStr<Err = String>>(name: &str) -> PyResult<T> {
    name.parse().map_err(crate::error::input_error)
}

/// The choice `obj` names (a str), for the argument `arg`; `None` where it is `None`.
pub fn named<T>(obj: Option<&Bound<'_, PyAny>>, arg: &str) -> PyResult<Option<T>>
where
    T: FromStr,
    T::Err: std::fmt::Display,
{
    crate::argument::text_or_none(obj, arg, "a str")?
        .map(|name| {
            name.parse()
                .map_err(|e| crate::error::input_error(format!("{arg}={name:?}: {e:#}")))
        })
        .transpose()
}

/// [`named`], the choice `default` names where `obj` is `None`.
pub fn named_or<T>(obj: Option<&Bound<'_, PyAny>>, arg: &str, default: &str) -> PyResult<T>
where
    T: FromStr,
    T::Err: std::fmt::Display,
{
    match named(obj, arg)? {
        Some(t) => Ok(t),
        None => default
            .parse()
            .map_err(|e| crate::error::input_error(format!("{arg}={default:?}: {e:#}"))),
    }
}

/// The engine `device` ("cpu", "gpu", "wgpu" or "auto") names, resolved as `--device` is; an
/// NprtError where the device does not open.
pub fn engine(device: &str) -> PyResult<Engine> {
    parse::<Compute>(device)?.engine().or_py()
}

/// [`engine`] of the `device` argument as Python passes it (a str; "cpu" where it is `None`).
pub fn engine_arg(device: Option<&Bound<'_, PyAny>>) -> PyResult<Engine> {
    let device = crate::argument::text_or_none(device, "device", "a str: cpu, gpu, wgpu or auto")?;
    engine(device.as_deref().unwrap_or("cpu"))
}
