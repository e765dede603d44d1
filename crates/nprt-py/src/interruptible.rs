//! Long calls that Ctrl-C stops within a moment: the work runs on a thread of its own while
//! the calling thread, which Python delivers signals to, watches for Ctrl-C; on it the work is
//! asked to stop (`nprt_io::interrupt`), ends at its next row, view or frame with nothing
//! half-written, and the call raises `nprt.Interrupted`.

use std::time::Duration;

use pyo3::prelude::*;

use crate::error::{check_interrupt, to_py, Interrupted};

/// Runs `work` with the GIL released, stopping it on Ctrl-C (see the module's note).
pub fn interruptible<R: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> anyhow::Result<R> + Send,
) -> PyResult<R> {
    nprt_io::interrupt::clear();
    let outcome = py.detach(|| {
        std::thread::scope(|s| {
            let worker = s.spawn(work);
            while !worker.is_finished() {
                std::thread::sleep(Duration::from_millis(50));
                if let Err(e) = Python::attach(check_interrupt) {
                    nprt_io::interrupt::request();
                    // Its result, partial, is not the call's.
                    let _ = worker.join();
                    return Err(e);
                }
            }
            worker
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
                .map_err(
                    |e| match e.downcast_ref::<nprt_io::interrupt::Interrupted>() {
                        Some(i) => Interrupted::new_err(i.to_string()),
                        None => to_py(e),
                    },
                )
        })
    });
    nprt_io::interrupt::clear();
    outcome
}
