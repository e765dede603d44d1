//! One view's OpenEXR file: read back and checked against its manifest record.

use std::path::Path;

use anyhow::{bail, Result};
use nprt_trace::exr_io::read_channels;
use nprt_trace::Frame;

use super::manifest::ViewRecord;

/// Checks that a view file reads back complete: right size, every channel, finite values.
pub fn check_view(path: &Path, view: &ViewRecord) -> Result<()> {
    read_view(path, view).map(|_| ())
}

/// Reads a view file, refusing one whose size disagrees with its record, that lacks a channel
/// or that holds non-finite values.
pub fn read_view(path: &Path, view: &ViewRecord) -> Result<Frame> {
    let (w, h, ch) = read_channels(path)?;
    if (w, h) != (view.width as usize, view.height as usize) {
        bail!("is {w}×{h}, expected {}×{}", view.width, view.height);
    }
    Frame::from_channels(w, h, &ch)
}
