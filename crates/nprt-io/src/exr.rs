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

/// Reads every f32/f16 channel of the first layer: (width, height, name → data).
pub fn read_channels(path: &Path) -> Result<(usize, usize, HashMap<String, Vec<f32>>)> {
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
}
