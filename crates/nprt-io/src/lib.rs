//! nprt-io: how every nprt stage touches the file system and the terminal. It owns writing
//! files so that no run ever leaves a half-written one (a temporary file renamed into place),
//! checking early that an output folder is writable, and the one style of progress bar with an
//! ETA. It sits at the bottom of the stack and must know nothing of scenes, images or networks:
//! callers hand it bytes or a closure that writes a file.
//!
//! ```
//! let dir = std::env::temp_dir().join(format!("nprt-io-doc-{}", std::process::id()));
//! let path = dir.join("notes/results.json");
//! nprt_io::check_writable(&path).unwrap();
//! nprt_io::write_file(&path, b"{\"l1\": 0.05}").unwrap();
//! assert_eq!(std::fs::read(&path).unwrap(), b"{\"l1\": 0.05}");
//! # std::fs::remove_dir_all(&dir).unwrap();
//! ```

mod atomic;
mod progress;

pub use atomic::{check_writable, create_parent_dir, write_atomically, write_file};
pub use progress::progress_bar;
