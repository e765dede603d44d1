//! What this machine has, checked before anything large is allocated or spawned: a size that
//! cannot fit is refused with the limit it broke, instead of growing until the kernel kills
//! the process or an allocation aborts it.

use anyhow::{bail, Result};

/// Bytes of memory a new allocation can take now: the system's available memory, or the
/// free memory of the process's cgroup (a container's limit) when that is smaller.
pub fn available_memory() -> u64 {
    let mut sys = sysinfo::System::new();
    sys.refresh_memory();
    let system = sys.available_memory();
    match sys.cgroup_limits() {
        Some(cgroup) if cgroup.free_memory > 0 => system.min(cgroup.free_memory),
        _ => system,
    }
}

/// Refuses `bytes` of `what` ("a 100000×100000 frame") when they exceed the available memory.
pub fn ensure_memory(bytes: u128, what: &str) -> Result<()> {
    let available = available_memory();
    if bytes > available as u128 {
        bail!(
            "{what} needs {}, more than the {} of memory available here",
            gib(bytes),
            gib(available as u128)
        );
    }
    Ok(())
}

fn gib(bytes: u128) -> String {
    format!("{:.1} GiB", bytes as f64 / (1u64 << 30) as f64)
}

/// The most worker threads a run may ask for: 8 per core, so that oversubscription to hide
/// I/O stays possible but a typo (`--threads 100000`) does not spawn threads for minutes.
pub fn thread_limit() -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    8 * cores
}

/// Refuses a worker-thread count of 0 or above [`thread_limit`], given by `source` (a flag or
/// an environment variable).
pub fn check_threads(n: usize, source: &str) -> Result<()> {
    let limit = thread_limit();
    if n == 0 || n > limit {
        bail!(
            "{source} {n} is not in 1..={limit} (8 per core of the {} cores here)",
            limit / 8
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_beyond_the_machine_are_refused_with_the_limit() {
        let available = available_memory();
        assert!(available > 0);
        ensure_memory(1 << 20, "a small buffer").unwrap();
        let err = ensure_memory(available as u128 * 2, "a huge frame")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("a huge frame needs") && err.contains("GiB"),
            "{err}"
        );
        check_threads(1, "--threads").unwrap();
        check_threads(thread_limit(), "--threads").unwrap();
        for n in [0, thread_limit() + 1, 100_000] {
            let err = check_threads(n, "--threads").unwrap_err().to_string();
            assert!(err.contains(&format!("--threads {n}")), "{err}");
        }
    }
}
