//! Inputs are regular files: one is checked by kind before it is opened, since opening a FIFO
//! for reading waits for a writer, for ever (`dataset verify` on a view file made a FIFO hung),
//! and a device or a folder is no input either. Links are followed: a link to a regular file is
//! a regular file.

use std::fs::FileType;
use std::path::Path;

use anyhow::{bail, Context, Result};

/// Refuses `path` if something other than a regular file is there (following links), naming
/// what it is; a missing path passes, for the reader's own "cannot read" to name.
pub fn check_input(path: &Path) -> Result<()> {
    match std::fs::metadata(path) {
        Ok(meta) if !meta.is_file() => bail!(
            "'{}' is a {}, not a regular file",
            path.display(),
            file_kind(&meta.file_type())
        ),
        _ => Ok(()),
    }
}

/// The bytes of the input file `path`, checked by [`check_input`] first.
pub fn read_input(path: &Path) -> Result<Vec<u8>> {
    check_input(path)?;
    std::fs::read(path).with_context(|| format!("cannot read '{}'", path.display()))
}

/// The text of the input file `path`, checked by [`check_input`] first.
pub fn read_input_string(path: &Path) -> Result<String> {
    check_input(path)?;
    std::fs::read_to_string(path).with_context(|| format!("cannot read '{}'", path.display()))
}

/// What a file system entry is, in words.
pub(crate) fn file_kind(t: &FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "FIFO";
        }
        if t.is_block_device() || t.is_char_device() {
            return "device";
        }
        if t.is_socket() {
            return "socket";
        }
    }
    if t.is_symlink() {
        "symbolic link"
    } else if t.is_dir() {
        "folder"
    } else if t.is_file() {
        "regular file"
    } else {
        "special file"
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    /// A FIFO, a device and a folder are refused by kind, without blocking; a link to a file
    /// is read through; a missing path is left to the reader.
    #[test]
    fn only_regular_files_are_inputs() {
        let dir = std::env::temp_dir().join(format!("nprt-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("fifo");
        let status = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(status.success());
        let err = read_input(&fifo).unwrap_err().to_string();
        assert!(err.contains("is a FIFO"), "{err}");
        let err = read_input(Path::new("/dev/null")).unwrap_err().to_string();
        assert!(err.contains("is a device"), "{err}");
        assert!(check_input(&dir)
            .unwrap_err()
            .to_string()
            .contains("is a folder"));
        let file = dir.join("file.txt");
        std::fs::write(&file, b"text").unwrap();
        let link = dir.join("link");
        std::os::unix::fs::symlink(&file, &link).unwrap();
        assert_eq!(read_input_string(&link).unwrap(), "text");
        assert!(check_input(&dir.join("missing")).is_ok());
        std::fs::remove_dir_all(&dir).ok();
    }
}
