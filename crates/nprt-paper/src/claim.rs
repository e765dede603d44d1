//! What an output folder is for: its first run records its settings there once they hold, and
//! a later run with other settings is refused rather than mixed into it (`nprt paper`, `nprt
//! demo`, `nprt bake`).

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

/// A folder's record, to write once the run's settings have been taken.
pub struct Claim {
    file: PathBuf,
    what: serde_json::Value,
}

impl Claim {
    /// None where `out`/`name` records `what` already; the record to write where it records
    /// nothing; an error naming both where it records another `kind` of run.
    pub fn check(
        out: &Path,
        name: &str,
        kind: &str,
        what: serde_json::Value,
    ) -> Result<Option<Claim>> {
        let file = out.join(name);
        if std::fs::symlink_metadata(&file).is_err() {
            return Ok(Some(Claim { file, what }));
        }
        // Read as every input is: a FIFO there is refused, not waited on.
        let bytes = nprt_io::read_input(&file)?;
        let before = crate::readback::experiment_record(&bytes, &file)?;
        if before != what {
            let said = before.to_string();
            let said = match said.chars().count() > 400 {
                true => format!("a record of {} characters", said.len()),
                false => said,
            };
            bail!(
                "'{}' holds another {kind} ({said}); this one is {what}: give another output \
                 folder, or remove it to start again",
                out.display(),
            );
        }
        Ok(None)
    }

    pub fn write(&self) -> Result<()> {
        nprt_io::write_file(&self.file, serde_json::to_vec_pretty(&self.what)?)
    }
}
