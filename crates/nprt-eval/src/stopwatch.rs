//! Wall-clock time as the evaluation reports it.

use std::time::Instant;

/// Milliseconds since `t`.
pub(crate) fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}
