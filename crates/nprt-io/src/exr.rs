//! Multi-channel OpenEXR files of f32 channels, written atomically (temporary file, then
//! rename) so a killed run never leaves a half-written image, and never holding a NaN or an
//! infinity: an image that would is a failed run, not an output.

use std::collections::HashMap;
use std::path::Path;

use ::exr::prelude::*;
use anyhow::{bail, Context, Result};

use crate::atomic::write_atomically;

/// Writes `channels` (name, row-major data of `width × height`) to `path`; refuses non-finite
/// values, naming the channel and pixel.
pub fn write_channels(
    path: &Path,
    width: usize,
    height: usize,
    channels: &[(String, Vec<f32>)],
) -> Result<()> {
    for (name, data) in channels {
        if data.len() != width * height {
            bail!(
                "channel '{name}' has {} values for a {width}×{height} image",
                data.len()
            );
        }
        if let Some(i) = data.iter().position(|v| !v.is_finite()) {
            bail!(
                "refusing to write '{}': channel '{name}' is {} at pixel ({}, {})",
                path.display(),
                data[i],
                i % width,
                i / width
            );
        }
    }
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .iter()
        .map(|(n, d)| AnyChannel::new(n.as_str(), FlatSamples::F32(d.clone())))
        .collect();
    let layer = Layer::new(
        (width, height),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    write_atomically(path, |tmp| {
        Image::from_layer(layer).write().to_file(tmp)?;
        Ok(())
    })
}

/// The size of `path`'s first layer as its header states it, read without decoding a pixel;
/// refuses a size the memory here cannot decode (a corrupt header claimed gigabytes, which the
/// decoder allocated before finding the data malformed).
pub fn checked_size(path: &Path) -> Result<(usize, usize)> {
    crate::check_input(path)?;
    let meta = ::exr::meta::MetaData::read_from_file(path, false)
        .with_context(|| format!("cannot read '{}'", path.display()))?;
    let header = meta
        .headers
        .first()
        .with_context(|| format!("'{}' has no layers", path.display()))?;
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    let channels = header.channels.list.len().max(1) as u128;
    // Each channel decoded once as stored and once as f32.
    crate::ensure_memory(
        w as u128 * h as u128 * channels * 8,
        &format!(
            "decoding '{}' ({w}×{h}, {channels} channels)",
            path.display()
        ),
    )?;
    Ok((w, h))
}

/// Reads every f32/f16 channel of the first layer: (width, height, name → data), after
/// [`checked_size`].
pub fn read_channels(path: &Path) -> Result<(usize, usize, HashMap<String, Vec<f32>>)> {
    checked_size(path)?;
    let image = read_all_flat_layers_from_file(path)
        .with_context(|| format!("cannot read '{}'", path.display()))?;
    let layer = image
        .layer_data
        .first()
        .with_context(|| format!("'{}' has no layers", path.display()))?;
    let (w, h) = (layer.size.width(), layer.size.height());
    let mut out = HashMap::new();
    for ch in &layer.channel_data.list {
        out.insert(
            ch.name.to_string(),
            ch.sample_data.values_as_f32().collect(),
        );
    }
    Ok((w, h, out))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_pixels_are_refused_by_channel_and_pixel() {
        let dir = std::env::temp_dir().join(format!("nprt-io-exr-{}", std::process::id()));
        let path = dir.join("x.exr");
        let mut data = vec![0.25f32; 4 * 2];
        write_channels(&path, 4, 2, &[("R".into(), data.clone())]).unwrap();
        assert_eq!(read_channels(&path).unwrap().2["R"], data);
        data[6] = f32::NAN;
        let err = write_channels(&path, 4, 2, &[("R".into(), data)]).unwrap_err();
        assert!(
            format!("{err}").contains("channel 'R' is NaN at pixel (2, 1)"),
            "{err}"
        );
        let rgb = [glam::Vec3::ONE, glam::Vec3::new(0.0, f32::INFINITY, 0.0)];
        let png = dir.join("x.png");
        let err = crate::write_png(&rgb, 2, 1, 0.0, &png).unwrap_err();
        assert!(
            format!("{err}").contains("pixel (1, 0)") && !png.exists(),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A header claiming a huge image (found by fuzzing: the decoder allocated 10 GB before
    /// finding the data malformed) is refused from the header alone.
    #[test]
    fn sizes_are_read_from_the_header_and_huge_ones_refused() {
        let dir = std::env::temp_dir().join(format!("nprt-io-exr-size-{}", std::process::id()));
        let path = dir.join("x.exr");
        write_channels(&path, 4, 2, &[("R".into(), vec![1.0; 8])]).unwrap();
        assert_eq!(checked_size(&path).unwrap(), (4, 2));
        let mut bytes = std::fs::read(&path).unwrap();
        let name = b"dataWindow\0box2i\0";
        let at = bytes.windows(name.len()).position(|w| w == name).unwrap() + name.len();
        // size (4 bytes), then x_min, y_min, x_max, y_max: both maxima become 2^20.
        for field in [12, 16] {
            bytes[at + field..at + field + 4].copy_from_slice(&(1i32 << 20).to_le_bytes());
        }
        std::fs::write(&path, bytes).unwrap();
        let err = format!("{:#}", read_channels(&path).unwrap_err());
        assert!(
            err.contains("(1048577×1048577, 1 channels) needs") && err.contains("GiB"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
