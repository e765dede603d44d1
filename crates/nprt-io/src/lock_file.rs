//! Lock files: a plain file a run holds an advisory lock on. It is opened without following a
//! link (a `.lock` made a symbolic link to another file must not have that file truncated or
//! written to) and refused by kind if it is not a regular file.

use std::fs::{File, OpenOptions};
use std::path::Path;

use anyhow::{bail, Context, Result};

use crate::input_file::file_kind;

/// Opens (creating it if need be, never truncating it) the lock file `path` for reading and
/// writing; refuses a symbolic link, a FIFO, a device or a folder there, naming it.
pub fn open_lock_file(path: &Path) -> Result<File> {
    if let Ok(meta) = std::fs::symlink_metadata(path) {
        if !meta.file_type().is_file() {
            bail!(
                "lock file '{}' is a {}, not a plain file: remove it (nprt makes it anew)",
                path.display(),
                file_kind(&meta.file_type())
            );
        }
    }
    let mut options = OpenOptions::new();
    options.read(true).write(true).create(true).truncate(false);
    // A link made between the check above and the open is not followed either.
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NOFOLLOW);
    options
        .open(path)
        .with_context(|| format!("cannot open lock file '{}'", path.display()))
}

/// Takes the folder `dir` for this run until the returned file is dropped (the OS releases it
/// if the process dies): its `.lock` holds an advisory lock and this process's id. A second
/// run on the same folder is refused by name, `what` saying what the folder is (a "model
/// folder", an "experiment folder") and `flag` how to give another.
pub fn lock_folder(dir: &Path, what: &str, flag: &str) -> Result<File> {
    use std::io::Write;
    let path = dir.join(".lock");
    let mut file = open_lock_file(&path)?;
    if let Err(e) = file.try_lock() {
        let holder = std::fs::read_to_string(&path).unwrap_or_default();
        return Err(match e {
            std::fs::TryLockError::WouldBlock => anyhow::anyhow!(
                "{what} '{}' is in use by another run ({}); wait for it to end or use another {flag}",
                dir.display(),
                holder.trim()
            ),
            std::fs::TryLockError::Error(e) => {
                anyhow::Error::new(e).context(format!("cannot lock '{}'", path.display()))
            }
        });
    }
    file.set_len(0)
        .and_then(|()| write!(file, "pid {}", std::process::id()))
        .with_context(|| format!("cannot write '{}'", path.display()))?;
    Ok(file)
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    /// A lock file made a link to another file is refused, and the other file is untouched.
    #[test]
    fn a_linked_lock_file_is_refused_and_its_target_kept() {
        let dir = std::env::temp_dir().join(format!("nprt-lock-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let target = dir.join("precious.txt");
        std::fs::write(&target, b"keep me").unwrap();
        let lock = dir.join(".lock");
        std::os::unix::fs::symlink(&target, &lock).unwrap();
        let err = open_lock_file(&lock).unwrap_err().to_string();
        assert!(
            err.contains("symbolic link") && err.contains(".lock"),
            "{err}"
        );
        assert_eq!(std::fs::read(&target).unwrap(), b"keep me");
        // A plain one is opened, and its contents kept.
        std::fs::remove_file(&lock).unwrap();
        std::fs::write(&lock, b"pid 1").unwrap();
        open_lock_file(&lock).unwrap();
        assert_eq!(std::fs::read(&lock).unwrap(), b"pid 1");
        std::fs::remove_dir_all(&dir).ok();
    }
}
