//! Atomic file writes: a temporary file beside the target, renamed into place. A rename
//! replaces whatever is at the target, so the target is checked first: a symbolic link is
//! written through (its final target is the file replaced), and a folder, device, FIFO or
//! socket is refused rather than replaced by a regular file.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

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

/// Symbolic links followed before a chain is taken for a loop (Linux's own limit).
const MAX_LINKS: usize = 40;

/// The file a write to `path` replaces: `path` itself, or the end of its chain of symbolic
/// links (which may not exist yet). Refuses what a rename must not replace: a folder, a
/// device, a FIFO or a socket.
pub fn output_target(path: &Path) -> Result<PathBuf> {
    let mut target = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        let meta = match std::fs::symlink_metadata(&target) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(target),
            Err(e) => {
                return Err(e).with_context(|| format!("cannot inspect '{}'", target.display()))
            }
            Ok(meta) => meta,
        };
        let kind = meta.file_type();
        if kind.is_file() {
            return Ok(target);
        }
        if !kind.is_symlink() {
            bail!(
                "'{}' is {}, not a regular file; nprt writes a file beside it and renames it into place, which would replace it: give the path of a file",
                path.display(),
                special_kind(&kind)
            );
        }
        let link = std::fs::read_link(&target)
            .with_context(|| format!("cannot read the link '{}'", target.display()))?;
        target = match target.parent() {
            Some(dir) => dir.join(link),
            None => link,
        };
    }
    bail!(
        "'{}' is a chain of more than {MAX_LINKS} symbolic links (a loop?)",
        path.display()
    )
}

/// How a message names a file type that is neither a regular file nor a link.
fn special_kind(kind: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
        if kind.is_fifo() {
            return "a FIFO";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if kind.is_dir() {
        "a folder"
    } else {
        "not a regular file"
    }
}

/// Creates `path`'s folder, lets `write` fill a temporary file beside `path`, then renames it
/// into place, so readers never see a partial file and a killed run leaves none behind. Through
/// a symbolic link, the link's final target is the file replaced ([`output_target`]).
pub fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let target = output_target(path)?;
    let dir = create_parent_dir(&target)?;
    let name = target
        .file_name()
        .with_context(|| format!("output path '{}' has no file name", path.display()))?;
    let tmp = dir.join(temporary_name(name));
    if let Err(e) = write(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        return Err(e.context(format!("cannot write '{}'", path.display())));
    }
    std::fs::rename(&tmp, &target)
        .with_context(|| format!("cannot move '{}' into place", path.display()))
}

/// Lands the folder `path` whole: `fill` writes its files into a temporary folder beside it,
/// which is then renamed into place (replacing a folder there, as a re-run of a killed one
/// does), so that a reader finds all of it or none. Temporaries of `path` left by killed runs
/// are removed first: the caller holds `path`'s parent for its run (a training run's lock).
pub fn write_folder(path: &Path, fill: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let dir = create_parent_dir(path)?;
    let name = path
        .file_name()
        .with_context(|| format!("output folder '{}' has no name", path.display()))?;
    let claimed = name.to_string_lossy().into_owned();
    for (stale, target) in leftover_temporaries(dir)? {
        if target == claimed {
            remove_path(&stale)?;
        }
    }
    let tmp = dir.join(temporary_name(name));
    std::fs::create_dir(&tmp)
        .with_context(|| format!("cannot create folder '{}'", tmp.display()))?;
    if let Err(e) = fill(&tmp) {
        let _ = std::fs::remove_dir_all(&tmp);
        return Err(e.context(format!("cannot write '{}'", path.display())));
    }
    if std::fs::symlink_metadata(path).is_ok() {
        remove_path(path)?;
    }
    std::fs::rename(&tmp, path)
        .with_context(|| format!("cannot move '{}' into place", path.display()))
}

/// Removes a file or a folder with what it holds.
fn remove_path(path: &Path) -> Result<()> {
    let removed = match std::fs::symlink_metadata(path)?.is_dir() {
        true => std::fs::remove_dir_all(path),
        false => std::fs::remove_file(path),
    };
    removed.with_context(|| format!("cannot remove '{}'", path.display()))
}

const TMP_SUFFIX: &str = ".tmp";
/// The most bytes a file name may have (Linux, macOS and Windows alike).
const NAME_MAX: usize = 255;

/// The temporary file's name beside `name`: `.{name}.{pid}.tmp`, where the name part is cut to
/// a prefix and a hash of the whole if that would pass [`NAME_MAX`] (a long name the file
/// system accepts must not fail for its temporary's sake).
fn temporary_name(name: &std::ffi::OsStr) -> String {
    use std::hash::{Hash, Hasher};
    let name = name.to_string_lossy();
    let pid = std::process::id();
    let whole = format!(".{name}.{pid}{TMP_SUFFIX}");
    if whole.len() <= NAME_MAX {
        return whole;
    }
    let mut hasher = std::hash::DefaultHasher::new();
    name.hash(&mut hasher);
    // `~` and 16 hex digits replace the cut end.
    let mut cut = NAME_MAX - (whole.len() - name.len()) - 17;
    while !name.is_char_boundary(cut) {
        cut -= 1;
    }
    format!(
        ".{}~{:016x}.{pid}{TMP_SUFFIX}",
        &name[..cut],
        hasher.finish()
    )
}

/// The temporary files [`write_atomically`] left in `dir` (runs killed mid-write leave them),
/// each with the name of the file it was to become; none where `dir` does not exist.
pub fn leftover_temporaries(dir: &Path) -> Result<Vec<(PathBuf, String)>> {
    let entries = match std::fs::read_dir(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(vec![]),
        listed => listed.with_context(|| format!("cannot list '{}'", dir.display()))?,
    };
    let mut found = vec![];
    for entry in entries {
        let entry = entry.with_context(|| format!("cannot list '{}'", dir.display()))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        // `.{target}.{pid}.tmp`
        let target = name
            .strip_prefix('.')
            .and_then(|n| n.strip_suffix(TMP_SUFFIX))
            .and_then(|n| n.rsplit_once('.'))
            .filter(|(_, pid)| !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit()))
            .map(|(target, _)| target.to_string());
        if let Some(target) = target {
            found.push((entry.path(), target));
        }
    }
    found.sort();
    Ok(found)
}

/// Removes the [leftover temporaries](leftover_temporaries) in `dir` of the files `ours` claims
/// (given each file's path): another run's may be under way. Returns how many were removed.
pub fn remove_temporaries(dir: &Path, ours: impl Fn(&Path) -> bool) -> Result<usize> {
    let mut removed = 0;
    for (tmp, target) in leftover_temporaries(dir)? {
        if ours(&dir.join(target)) {
            remove_path(&tmp)?;
            removed += 1;
        }
    }
    Ok(removed)
}

/// Writes `bytes` to `path` atomically.
pub fn write_file(path: &Path, bytes: impl AsRef<[u8]>) -> Result<()> {
    write_atomically(path, |tmp| Ok(std::fs::write(tmp, bytes.as_ref())?))
}

/// Fails early, before a long job, if `path` cannot be written: refuses what
/// [`write_atomically`] would refuse, creates the folder and writes and removes a probe file there.
pub fn check_writable(path: &Path) -> Result<()> {
    let dir = create_parent_dir(&output_target(path)?)?.to_path_buf();
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
    fn a_folder_lands_whole_or_not_at_all() {
        let d = dir("folder");
        let path = d.join("snap");
        // A killed run's temporary and a broken folder from a build that wrote in place.
        std::fs::create_dir_all(d.join(".snap.1.tmp")).unwrap();
        std::fs::create_dir_all(&path).unwrap();
        std::fs::write(path.join("weights"), b"old").unwrap();
        let err = write_folder(&path, |tmp| {
            std::fs::write(tmp.join("weights"), b"new")?;
            bail!("killed before the config")
        });
        assert!(err.is_err());
        assert_eq!(std::fs::read(path.join("weights")).unwrap(), b"old");
        write_folder(&path, |tmp| {
            std::fs::write(tmp.join("weights"), b"new")?;
            Ok(std::fs::write(tmp.join("config"), b"c")?)
        })
        .unwrap();
        assert_eq!(std::fs::read(path.join("weights")).unwrap(), b"new");
        assert!(path.join("config").is_file());
        assert_eq!(leftover_temporaries(&d).unwrap(), vec![]);
        std::fs::remove_dir_all(&d).unwrap();
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

    /// A file name of 250 bytes (the file system takes up to 255) is written: its temporary's
    /// name is shortened to fit.
    #[test]
    fn a_long_file_name_is_written_through_a_shorter_temporary() {
        let d = dir("long");
        for name in ["a".repeat(250), format!("{}é", "b".repeat(252))] {
            let path = d.join(&name);
            write_file(&path, b"kept").unwrap();
            assert_eq!(std::fs::read(&path).unwrap(), b"kept");
            let tmp = temporary_name(std::ffi::OsStr::new(&name));
            assert!(tmp.len() <= NAME_MAX && tmp.ends_with(".tmp"), "{tmp}");
        }
        assert_eq!(
            temporary_name(std::ffi::OsStr::new("v.exr")),
            format!(".v.exr.{}.tmp", std::process::id())
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn leftovers_of_killed_writes_are_found_with_their_targets() {
        let d = dir("leftover");
        std::fs::create_dir_all(&d).unwrap();
        for name in [
            ".view_1.exr.1234.tmp",
            ".a.b.77.tmp",
            "view_2.exr",
            ".x.tmp",
            ".y.z9.tmp",
        ] {
            std::fs::write(d.join(name), "").unwrap();
        }
        let found = leftover_temporaries(&d).unwrap();
        let targets: Vec<&str> = found.iter().map(|(_, t)| t.as_str()).collect();
        assert_eq!(targets, ["a.b", "view_1.exr"]);
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

    #[cfg(unix)]
    #[test]
    fn links_are_written_through_and_special_files_refused() {
        let d = dir("special");
        std::fs::create_dir_all(d.join("real")).unwrap();
        let file = d.join("real/out.txt");
        write_file(&file, "old").unwrap();
        let link = d.join("link.txt");
        std::os::unix::fs::symlink("real/out.txt", &link).unwrap();
        write_file(&link, "new").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "new");
        // A dangling link creates its target.
        let dangling = d.join("dangling.txt");
        std::os::unix::fs::symlink("real/made.txt", &dangling).unwrap();
        write_file(&dangling, "made").unwrap();
        assert_eq!(
            std::fs::read_to_string(d.join("real/made.txt")).unwrap(),
            "made"
        );
        // A loop of links, a FIFO, a device and a folder are refused and left alone.
        std::os::unix::fs::symlink("loop.b", d.join("loop.a")).unwrap();
        std::os::unix::fs::symlink("loop.a", d.join("loop.b")).unwrap();
        let fifo = d.join("fifo");
        assert!(std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success());
        for (path, why) in [
            (d.join("loop.a"), "symbolic links"),
            (fifo.clone(), "a FIFO"),
            (PathBuf::from("/dev/null"), "a device"),
            (d.join("real"), "a folder"),
        ] {
            for err in [
                write_file(&path, "x").unwrap_err(),
                check_writable(&path).unwrap_err(),
            ] {
                let err = format!("{err:#}");
                assert!(
                    err.contains(why) && err.contains(&*path.to_string_lossy()),
                    "{err}"
                );
            }
        }
        use std::os::unix::fs::FileTypeExt;
        assert!(std::fs::symlink_metadata(&fifo)
            .unwrap()
            .file_type()
            .is_fifo());
        assert!(std::fs::symlink_metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn unwritable_folders_are_named() {
        let err = check_writable(Path::new("/proc/nprt-no/x")).unwrap_err();
        assert!(format!("{err:#}").contains("/proc/nprt-no"), "{err:#}");
    }
}
