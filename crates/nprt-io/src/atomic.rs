//! Atomic file writes: a temporary file beside the target, renamed into place.

use std::path::Path;

use anyhow::{Context, Result};

/// Creates the folder `path` goes in (the current one for a bare file name) and returns it.
pub fn create_parent_dir(path: &Path) -> Result<&Path> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create folder '{}'", dir.display()))?;
    Ok(dir)
}

/// Creates `path`'s folder, lets `write` fill a temporary file beside `path`, then renames it
/// into place, so readers never see a partial file and a killed run leaves none behind.
pub fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let dir = create_parent_dir(path)?;
    let name = path
        .file_name()
        .with_context(|| format!("output path '{}' has no file name", path.display()))?;
    let tmp = dir.join(format!(
        ".{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id()
    ));
    if let Err(e) = write(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        return Err(e.context(format!("cannot write '{}'", path.display())));
    }
    std::fs::rename(&tmp, path)
        .with_context(|| format!("cannot move '{}' into place", path.display()))
}

/// Writes `bytes` to `path` atomically.
pub fn write_file(path: &Path, bytes: impl AsRef<[u8]>) -> Result<()> {
    write_atomically(path, |tmp| Ok(std::fs::write(tmp, bytes.as_ref())?))
}

/// Fails early, before a long job, if `path` cannot be written: creates its folder and writes
/// and removes a probe file there.
pub fn check_writable(path: &Path) -> Result<()> {
    let dir = create_parent_dir(path)?;
    let probe = dir.join(format!(".nprt-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"")
        .with_context(|| format!("output folder '{}' is not writable", dir.display()))?;
    std::fs::remove_file(&probe).ok();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("nprt-io-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn a_failed_write_leaves_neither_file_nor_temporary() {
        let d = dir("fail");
        let path = d.join("out.bin");
        let err = write_atomically(&path, |tmp| {
            std::fs::write(tmp, b"half")?;
            anyhow::bail!("disk full")
        })
        .unwrap_err();
        assert!(format!("{err:#}").contains("out.bin") && format!("{err:#}").contains("disk full"));
        assert_eq!(
            std::fs::read_dir(&d).unwrap().count(),
            0,
            "nothing may be left behind"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_write_replaces_the_old_file_whole() {
        let d = dir("replace");
        let path = d.join("a/b.txt");
        write_file(&path, "first").unwrap();
        write_file(&path, "second").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "second");
        assert_eq!(
            std::fs::read_dir(path.parent().unwrap()).unwrap().count(),
            1
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn unwritable_folders_are_named() {
        let err = check_writable(Path::new("/proc/nprt-no/x")).unwrap_err();
        assert!(format!("{err:#}").contains("/proc/nprt-no"), "{err:#}");
    }
}
