//! nprt's errors as Python exceptions, defined in Python (`nprt.errors`, so that they pickle):
//! `NprtError` with the message the command line prints (the file and the reason, each cause
//! once), `InputError` for refused arguments and `Interrupted` for Ctrl-C.

use pyo3::PyErr;

pyo3::import_exception!(nprt.errors, NprtError);
pyo3::import_exception!(nprt.errors, InputError);
pyo3::import_exception!(nprt.errors, Interrupted);

/// `e` as an [`NprtError`] with its chain of causes, each said once, the command line's flags
/// in it named as Python's arguments.
pub fn to_py(e: anyhow::Error) -> PyErr {
    NprtError::new_err(pythonic(&nprt_io::describe_error(&e)))
}

/// The flags that are keyword arguments of the same name in Python (`--train-res` is
/// `train_res=`); others (`--help`, cargo's) are left as they are.
const KEYWORDS: &[&str] = &[
    "activation",
    "arch",
    "basis",
    "batch-size",
    "batch-views",
    "budget",
    "calibrate",
    "camera-path",
    "camera-volume",
    "data",
    "deep-shading",
    "denoise-direct",
    "device",
    "direct",
    "direct-spp",
    "encoder-width",
    "encoding",
    "envmaps",
    "epochs",
    "example-map",
    "example-res",
    "exposure",
    "fov",
    "fps",
    "frames",
    "jitter-exposure",
    "jitter-tint",
    "lighting",
    "look",
    "lr",
    "max-depth",
    "minutes",
    "mix-builtin",
    "mix-maps",
    "model",
    "nrc-warmup",
    "oracles",
    "out",
    "precision",
    "quality",
    "res",
    "scene",
    "schedule",
    "seed",
    "sh-spp",
    "shard",
    "shown-views",
    "snapshots",
    "spin",
    "spp",
    "spread",
    "targets",
    "temporal-frames",
    "temporal-res",
    "test-maps",
    "test-res",
    "test-spp",
    "test-views",
    "timing-res",
    "train-res",
    "train-views",
    "training-minutes",
    "transfer",
    "views",
    "volume-max",
    "volume-min",
];

/// `message` with each `--flag` that is a Python keyword written `flag=`.
fn pythonic(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(at) = rest.find("--") {
        out.push_str(&rest[..at]);
        let after = &rest[at + 2..];
        let len = after
            .find(|c: char| !(c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'))
            .unwrap_or(after.len());
        let flag = &after[..len];
        if KEYWORDS.contains(&flag) {
            out.push_str(&flag.replace('-', "_"));
            out.push('=');
        } else {
            out.push_str("--");
            out.push_str(flag);
        }
        rest = &after[len..];
    }
    out.push_str(rest);
    out
}

/// Python's pending signals handled: Ctrl-C as [`Interrupted`] (outputs are left as the command
/// line leaves them, resumable), any other handler's exception as it is.
pub fn check_interrupt(py: pyo3::Python<'_>) -> pyo3::PyResult<()> {
    py.check_signals().map_err(|e| {
        if e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) {
            Interrupted::new_err(
                "interrupted (Ctrl-C); what was written is kept and the same call resumes it",
            )
        } else {
            e
        }
    })
}

/// An argument refused: [`InputError`] (a `ValueError` too) with `message`.
pub fn input_error(message: impl Into<String>) -> PyErr {
    InputError::new_err(message.into())
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
