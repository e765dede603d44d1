//! Multi-channel OpenEXR files of f32 channels, written atomically (temporary file, then
//! rename) so a killed run never leaves a half-written image.

use std::collections::HashMap;
use std::path::Path;

use ::exr::prelude::*;
use anyhow::{bail, Context, Result};

use crate::atomic::write_atomically;

/// Writes `channels` (name, row-major data of `width × height`) to `path`.
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
