//! nprt-io: how every nprt stage touches the file system and the terminal. It owns writing
//! files so that no run ever leaves a half-written one (a temporary file renamed into place),
//! checking early that an output folder is writable (and never replacing a device, FIFO or
//! link target it was not asked to), inputs checked to be regular files (a FIFO
//! would block for ever), a mapped file cut short named instead of a bare SIGBUS, lock files opened without following links, checking sizes against the machine's memory and cores
//! before allocating, the one style of progress bar with an ETA, and the file formats of pixels: multi-channel OpenEXR, the one image reader (EXR, PNG,
//! JPEG, Radiance HDR as linear RGB), tone-mapped PNG, the sRGB curve, and line plots. It sits
//! at the bottom of the stack and must know nothing of scenes or networks: callers hand it
//! bytes, pixels or a closure that writes a file. It also says an error as every front end
//! says it (each cause once), and carries a front end's request to stop long work early.
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
mod bus_error;
mod error_text;
pub mod exr;
mod image_read;
mod image_write;
mod input_file;
pub mod interrupt;
mod limits;
mod lock_file;
mod plot;
mod png;
mod progress;
mod srgb;

pub use atomic::{
    check_writable, create_parent_dir, leftover_temporaries, output_target, remove_temporaries,
    write_atomically, write_file, write_folder,
};
pub use bus_error::name_on_bus_error;
pub use error_text::{describe_error, short_number};
pub use image_read::{linear_rgb, read_linear_rgb, LinearImage};
pub use image_write::write_linear_rgb;
pub use indicatif::ProgressBar;
pub use input_file::{check_input, read_input, read_input_string};
pub use limits::{available_memory, check_threads, ensure_memory, thread_limit};
pub use lock_file::{lock_folder, open_lock_file};
pub use plot::plot_lines;
pub use png::{srgb8, to_image, write_png};
pub use progress::{progress_bar, staged, StagedBar};
pub use srgb::{linear_to_srgb, srgb_to_linear};
