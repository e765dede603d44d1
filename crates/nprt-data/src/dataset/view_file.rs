//! One view's OpenEXR file: written from its render, read back and checked against its
//! manifest record. A test view rendered in two halves also holds the first half's radiance
//! (`half.R/G/B`), from which evaluation measures the reference's own noise; a training view of
//! a dataset made with `--transfer` holds its transfer vectors too.

use std::path::Path;

use anyhow::{bail, Context, Result};
use glam::Vec3;
use nprt_io::exr::{checked_size, read_channels, write_channels};
use nprt_scene::envmap::MAX_RADIANCE;
use nprt_trace::Frame;

use super::manifest::ViewRecord;
use super::transfer::Transfer;
use super::view_parts::ViewParts;

const HALF: [&str; 3] = ["half.R", "half.G", "half.B"];

/// What a view file holds.
pub struct ViewImage {
    pub frame: Frame,
    /// Radiance of the first half of the samples, for a view rendered in halves.
    pub half: Option<Vec<Vec3>>,
    /// The pixels' transfer vectors, for a training view of a dataset made with `--transfer`.
    pub transfer: Option<Transfer>,
}

/// Checks that a view file reads back complete: right size, every channel, finite values.
pub fn check_view(path: &Path, view: &ViewRecord, parts: ViewParts) -> Result<()> {
    read_view(path, view, parts).map(|_| ())
}

/// Writes a view file atomically.
pub fn write_view(path: &Path, image: &ViewImage) -> Result<()> {
    let f = &image.frame;
    let mut channels = f.channels();
    if let Some(half) = &image.half {
        for (k, name) in HALF.iter().enumerate() {
            channels.push((name.to_string(), half.iter().map(|v| v[k]).collect()));
        }
    }
    if let Some(t) = &image.transfer {
        channels.extend(t.channels());
    }
    // Each channel is held below the top of the range a reader accepts (a half's as radiance):
    // only a firefly under a map near the radiance limit could pass it.
    for (name, values) in &mut channels {
        if let Some((_, top)) = Frame::channel_range(name.strip_prefix("half.").unwrap_or(name)) {
            values.iter_mut().for_each(|v| *v = v.min(top));
        }
    }
    write_channels(path, f.width, f.height, &channels)
}

/// Reads a view file, refusing one whose size disagrees with its record, that lacks a channel
/// (of `parts` too) or that holds a value past its channel's range (radiance outside [0, 1e12],
/// reflectances, α or mask outside [0, 1], a transfer value that is not finite).
pub fn read_view(path: &Path, view: &ViewRecord, parts: ViewParts) -> Result<ViewImage> {
    // The size is checked from the header, before a corrupt one makes the decoder allocate.
    let (w, h) = checked_size(path)?;
    if (w, h) != (view.width as usize, view.height as usize) {
        bail!("is {w}×{h}, expected {}×{}", view.width, view.height);
    }
    let (_, _, ch) = read_channels(path)?;
    let frame = Frame::from_channels(w, h, &ch)?;
    let half = if parts.halves {
        let [r, g, b] = HALF.map(|name| {
            ch.get(name)
                .with_context(|| format!("lacks channel '{name}'"))
        });
        let (r, g, b) = (r?, g?, b?);
        if [r, g, b].iter().any(|c| c.len() != w * h) {
            bail!("a half.* channel does not hold {w}×{h} values");
        }
        let half: Vec<Vec3> = (0..w * h).map(|i| Vec3::new(r[i], g[i], b[i])).collect();
        if let Some(i) = half
            .iter()
            .position(|v| !v.is_finite() || v.min_element() < 0.0 || v.max_element() > MAX_RADIANCE)
        {
            bail!(
                "channel half.* is {} at pixel ({}, {}), not a radiance in [0, {MAX_RADIANCE:e}]",
                half[i],
                i % w,
                i / w
            );
        }
        Some(half)
    } else {
        None
    };
    let transfer = (parts.transfer)
        .map(|basis| Transfer::from_channels(basis, w * h, &ch))
        .transpose()?;
    Ok(ViewImage {
        frame,
        half,
        transfer,
    })
}
