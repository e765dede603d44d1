//! A request to stop long work early, for a front end that catches Ctrl-C itself (Python's
//! `nprt` package: the interpreter owns SIGINT, so the process does not end). Long loops ask
//! between units of work (a row of pixels, a view, a frame, an evaluation's stage) and end
//! with [`Interrupted`], writing nothing half-made: what they wrote before stays, resumable
//! as after a killed command. The command line never requests it: Ctrl-C ends its process.

use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// The error a stopped call ends with.
#[derive(Debug)]
pub struct Interrupted;

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("interrupted; what was written is kept, and the same call resumes it")
    }
}

impl std::error::Error for Interrupted {}

/// Asks every long loop under way to stop at its next unit of work.
pub fn request() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Withdraws the request (a front end does so before its next call).
pub fn clear() {
    REQUESTED.store(false, Ordering::SeqCst);
}

/// Whether a stop is requested: loops that cannot return an error skip their remaining work,
/// and their caller's next [`check`] ends the call.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// [`Interrupted`] where a stop is requested.
pub fn check() -> anyhow::Result<()> {
    if requested() {
        return Err(Interrupted.into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_request_stops_checks_until_cleared() {
        assert!(check().is_ok());
        request();
        let e = check().unwrap_err();
        assert!(e.is::<Interrupted>(), "{e}");
        clear();
        assert!(check().is_ok());
    }
}
