//! Which shard of a dataset this process renders when the command line does not say: the task
//! of a Slurm job array (scripts/slurm-generate), so that one sbatch line serves every task.

use anyhow::{bail, Result};

/// The shard `(K, N)` of the Slurm array task this process runs in, if it runs in one:
/// K = (SLURM_ARRAY_TASK_ID − MIN) / STEP and N = SLURM_ARRAY_TASK_COUNT.
pub fn shard_from_env() -> Result<Option<(u64, u64)>> {
    shard_from(|name| std::env::var(name).ok())
}

fn shard_from(var: impl Fn(&str) -> Option<String>) -> Result<Option<(u64, u64)>> {
    let number = |name: &str, default: Option<u64>| -> Result<Option<u64>> {
        match var(name) {
            None => Ok(default),
            Some(text) => match text.trim().parse() {
                Ok(n) => Ok(Some(n)),
                Err(_) => bail!("{name} is '{text}', not a whole number"),
            },
        }
    };
    let (Some(id), Some(count)) = (
        number("SLURM_ARRAY_TASK_ID", None)?,
        number("SLURM_ARRAY_TASK_COUNT", None)?,
    ) else {
        return Ok(None);
    };
    let min = number("SLURM_ARRAY_TASK_MIN", Some(0))?.unwrap_or(0);
    let step = number("SLURM_ARRAY_TASK_STEP", Some(1))?
        .unwrap_or(1)
        .max(1);
    let offset = id.checked_sub(min).filter(|o| o % step == 0);
    match offset.map(|o| o / step) {
        Some(k) if k < count => Ok(Some((k, count))),
        _ => bail!(
            "Slurm array task {id} (min {min}, step {step}, {count} tasks) is not one of {count} evenly spaced shards: submit the array as --array=0-{}, or give --shard K/N",
            count.saturating_sub(1)
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn from(vars: &[(&str, &str)]) -> Result<Option<(u64, u64)>> {
        shard_from(|name| {
            vars.iter()
                .find(|(n, _)| *n == name)
                .map(|(_, v)| v.to_string())
        })
    }

    #[test]
    fn array_tasks_become_shards() {
        assert_eq!(from(&[]).unwrap(), None);
        let task = |id| from(&[("SLURM_ARRAY_TASK_ID", id), ("SLURM_ARRAY_TASK_COUNT", "4")]);
        assert_eq!(task("3").unwrap(), Some((3, 4)));
        // --array=10-16:2 has tasks 10, 12, 14, 16.
        let stepped = from(&[
            ("SLURM_ARRAY_TASK_ID", "14"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
            ("SLURM_ARRAY_TASK_MIN", "10"),
            ("SLURM_ARRAY_TASK_STEP", "2"),
        ]);
        assert_eq!(stepped.unwrap(), Some((2, 4)));
        // --array=0,5,9 is no set of shards; neither is a number that is not one.
        let err = from(&[
            ("SLURM_ARRAY_TASK_ID", "9"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ]);
        assert!(err.unwrap_err().to_string().contains("--array=0-2"));
        let err = task("x").unwrap_err().to_string();
        assert!(err.contains("SLURM_ARRAY_TASK_ID is 'x'"), "{err}");
    }
}
