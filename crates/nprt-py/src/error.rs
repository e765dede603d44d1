//! nprt's errors as a Python exception: `nprt.NprtError`, with the message the command line
//! prints (the file and the reason, each cause after a colon).

use pyo3::create_exception;
use pyo3::exceptions::PyRuntimeError;
use pyo3::PyErr;

create_exception!(
    nprt,
    NprtError,
    PyRuntimeError,
    "An error of nprt's: bad input (the file and the reason) or a failed stage."
);

/// `e` as an [`NprtError`] with its chain of causes.
pub fn to_py(e: anyhow::Error) -> PyErr {
    NprtError::new_err(format!("{e:#}"))
}

/// [`to_py`] on a result.
pub trait OrPy<T> {
    fn or_py(self) -> pyo3::PyResult<T>;
}

impl<T> OrPy<T> for anyhow::Result<T> {
    fn or_py(self) -> pyo3::PyResult<T> {
        self.map_err(to_py)
    }
}
