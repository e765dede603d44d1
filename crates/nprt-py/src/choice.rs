//! Named choices from Python strings, as the command line takes them: `device="gpu"`,
//! `arch="dsep"`, `precision="f16"`, … (each accepted name stated once, in nprt-net).

use std::str::FromStr;

use nprt_net::{Compute, Engine};
use pyo3::PyResult;

use crate::error::OrPy;

/// `name` as a `T`; an InputError (a ValueError) listing the accepted names otherwise.
pub fn parse<T: FromStr<Err = String>>(name: &str) -> PyResult<T> {
    name.parse().map_err(crate::error::input_error)
}

/// The engine `device` ("cpu", "gpu", "wgpu" or "auto") names, resolved as `--device` is; an
/// NprtError where the device does not open.
pub fn engine(device: &str) -> PyResult<Engine> {
    parse::<Compute>(device)?.engine().or_py()
}
