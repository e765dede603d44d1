//! A Deep Shading model folder: `deep-shading.json`, the weights, and shading with them.

use std::path::Path;

use anyhow::{bail, Context, Result};
use glam::Vec3;
use nprt_scene::EnvMap;
use nprt_trace::GBuffer;
use serde::{Deserialize, Serialize};

use super::options::DeepShadingOptions;
use super::unet::feature_image;
use crate::engine::Engine;
use crate::init::Init;
use crate::model::folder::{check_bounds, check_whole, load_weights, read_config, WEIGHTS_FILE};
use crate::network::encoder::{check_input_width, LightInput};
use crate::network::unet::DeepShading;
use crate::shading::UnetShading;

pub const TAG: &str = "deep-shading";
pub const CONFIG_FILE: &str = "deep-shading.json";

/// The model folder's config.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DeepShadingFile {
    pub format: String,
    pub version: u32,
    pub encoder_width: usize,
    pub bounds: [[f32; 3]; 2],
    pub scene: String,
    pub scene_hash: String,
    pub dataset_hash: String,
    pub unet_params: usize,
    pub encoder_params: usize,
    pub options: DeepShadingOptions,
    pub epochs_done: usize,
    pub seconds: f64,
    /// BLAKE3 of the weights file this config was saved with (as a model folder's `model.json`
    /// names it: [`check_whole`]); absent in older files.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights_blake3: Option<String>,
}

/// A trained Deep Shading network, ready to shade.
pub struct DeepShadingModel {
    pub file: DeepShadingFile,
    /// The network on the engine it was loaded for.
    net: Box<dyn UnetShading>,
}

/// Reads a Deep Shading folder's config, refusing an encoder width no network can have.
pub fn read_file(dir: &Path) -> Result<DeepShadingFile> {
    let file: DeepShadingFile = read_config(dir, CONFIG_FILE, TAG, 1, "Deep Shading model")?;
    check_input_width(file.encoder_width)
        .and_then(|()| check_bounds(&file.bounds))
        .with_context(|| format!("Deep Shading model '{}'", dir.display()))?;
    if !(file.seconds.is_finite() && file.seconds >= 0.0) {
        bail!(
            "Deep Shading model '{}' says it trained {} s; the file is damaged",
            dir.display(),
            nprt_io::short_number(file.seconds)
        );
    }
    Ok(file)
}

impl DeepShadingModel {
    /// Loads the network in `dir` to shade on `engine`.
    pub fn load(dir: &Path, engine: Engine) -> Result<Self> {
        let file = read_file(dir)?;
        let mut net = DeepShading::new(&mut Init::new(0), file.encoder_width);
        let hash = load_weights(&dir.join(WEIGHTS_FILE), &mut net, TAG)?;
        let counts = [net.unet_params(), crate::Parameters::num_params(&net.light)];
        if [file.unet_params, file.encoder_params] != counts {
            bail!(
                "Deep Shading model '{}': its {CONFIG_FILE} counts {} U-Net and {} encoder \
                 parameters, its network has {} and {}; the file is damaged",
                dir.display(),
                file.unet_params,
                file.encoder_params,
                counts[0],
                counts[1]
            );
        }
        check_whole(dir, CONFIG_FILE, file.weights_blake3.as_deref(), &hash)?;
        Ok(DeepShadingModel {
            file,
            net: engine.unet(net)?,
        })
    }

    /// Radiance of every pixel of a `width`×`height` G-buffer under `map` rotated by
    /// `rotation_deg` (background pixels 0).
    pub fn shade(
        &self,
        g: &GBuffer,
        width: usize,
        height: usize,
        map: &EnvMap,
        rotation_deg: f32,
    ) -> Vec<Vec3> {
        let (img, pw, ph) = feature_image(&self.file.bounds, g, width, height);
        let light = LightInput::new(
            map,
            rotation_deg,
            self.file.encoder_width,
            self.file.options.map_norm,
        );
        let v = self.net.radiance(img, light, (ph, pw));
        (0..width * height)
            .map(|i| {
                let (x, y) = (i % width, i / width);
                if g.mask[i] > 0.5 {
                    Vec3::new(
                        v[y * pw + x],
                        v[pw * ph + y * pw + x],
                        v[2 * pw * ph + y * pw + x],
                    )
                } else {
                    Vec3::ZERO
                }
            })
            .collect()
    }
}
