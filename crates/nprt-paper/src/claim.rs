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
        if let Ok(bytes) = std::fs::read(&file) {
            let before = crate::readback::experiment_record(&bytes, &file)?;
            if before != what {
                bail!(
                    "'{}' holds another {kind} ({}); this one is {}: give another output folder, or remove it to start again",
                    out.display(),
                    before,
                    what
                );
            }
            return Ok(None);
        }
        Ok(Some(Claim { file, what }))
    }

    pub fn write(&self) -> Result<()> {
        nprt_io::write_file(&self.file, serde_json::to_vec_pretty(&self.what)?)
    }
}
