//! Model description: the config that travels with the weights, and the layer table.

use std::path::Path;

use anyhow::{bail, Context, Result};
use burn::module::Module;
use burn::store::{ModuleSnapshot, SafetensorsStore};
use burn::tensor::Device;
use serde::{Deserialize, Serialize};

use crate::activation::Activation;
use crate::design::{Design, NprtNet};
use crate::direct_light::DirectLight;
use crate::init::Init;
use crate::map_norm::MapNorm;
use crate::position_encoding::PositionEncoding;

/// Identifies a model folder's config file.
pub const MODEL_FORMAT: &str = "nprt-model";
/// Bumped whenever a saved model would be read differently.
pub const MODEL_VERSION: u32 = 1;
pub const CONFIG_FILE: &str = "model.json";
pub const WEIGHTS_FILE: &str = "weights.safetensors";

/// One row of `nprt model info`.
pub struct LayerRow {
    pub name: String,
    pub shape: String,
    pub params: usize,
}

/// Everything needed to rebuild a network, besides its weights.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelConfig {
    pub design: Design,
    pub activation: Activation,
    /// Width W of the encoder's W × W/2 input map.
    pub encoder_width: usize,
    /// How the map is normalised for the encoder (absent in older files: the paper's mean).
    #[serde(default)]
    pub map_norm: MapNorm,
    /// Whether the network predicts direct light or leaves it to the tracer (absent in older
    /// files: learned, as in the paper). Written only when traced, so that a learned model's
    /// file and run key stay what they were and its unfinished runs still resume.
    #[serde(default, skip_serializing_if = "DirectLight::is_learned")]
    pub direct: DirectLight,
    /// How the transport network sees the position (absent in older files: as the paper
    /// does). Written only for a hash grid, for the same reason as `direct`.
    #[serde(default, skip_serializing_if = "PositionEncoding::is_none")]
    pub encoding: PositionEncoding,
}

/// Encoder input width when none is asked for: on the demo, 64 measured 10% worse in L1 than
/// 128 for 10% less training time.
pub const DEFAULT_ENCODER_WIDTH: usize = 128;

/// Map normalisation when none is asked for: per channel, better than the paper's single mean in
/// every error measured on held-out maps, though not yet in their colour balance (docs/model.md).
pub const DEFAULT_MAP_NORM: MapNorm = MapNorm::Channel;

impl ModelConfig {
    pub fn new(design: Design, activation: Option<Activation>) -> Self {
        ModelConfig {
            design,
            activation: activation.unwrap_or(design.default_activation()),
            encoder_width: DEFAULT_ENCODER_WIDTH,
            map_norm: DEFAULT_MAP_NORM,
            direct: DirectLight::Learned,
            encoding: PositionEncoding::None,
        }
    }

    /// The design's name, marked `+grid` with a hash grid and `+direct` when direct light is
    /// traced: how reports name it.
    pub fn label(&self) -> String {
        let grid = match self.encoding {
            PositionEncoding::None => "",
            PositionEncoding::HashGrid => "+grid",
        };
        let direct = match self.direct {
            DirectLight::Learned => "",
            DirectLight::Traced => "+direct",
        };
        format!("{}{grid}{direct}", self.design.name())
    }

    pub fn build(&self, init: &mut Init) -> NprtNet {
        NprtNet::new(
            init,
            self.design,
            self.activation,
            self.encoder_width,
            self.encoding,
        )
    }
}

/// The config file of a model folder: what to build, how to feed it, where it came from.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ModelFile {
    pub format: String,
    pub version: u32,
    #[serde(flatten)]
    pub config: ModelConfig,
    /// Scene bounds that normalise positions to [−1, 1].
    pub bounds: [[f32; 3]; 2],
    /// The scene the model was trained for, as the dataset names it (a file path or a
    /// built-in name), and its BLAKE3 hash as in the dataset manifest.
    #[serde(default)]
    pub scene: String,
    pub scene_hash: String,
    /// BLAKE3 of the training dataset's manifest.json.
    pub dataset_hash: String,
    pub transport_params: usize,
    pub encoder_params: usize,
    /// Training settings and progress (informative).
    pub training: serde_json::Value,
    /// What the network's radiance is multiplied by, per channel, to have its training targets'
    /// level (`nprt train --calibrate level`, crate::calibration); absent: as the network says.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub level_gain: Option<[f32; 3]>,
}

impl ModelFile {
    /// The gain on each channel of the network's radiance (1 without calibration).
    pub fn output_gain(&self) -> [f32; 3] {
        self.level_gain.unwrap_or([1.0; 3])
    }
}

/// Writes `model.json` and the weights of `net` into `dir`, each file atomically.
pub fn save_model(dir: &Path, file: &ModelFile, net: &NprtNet) -> Result<()> {
    save_weights(&dir.join(WEIGHTS_FILE), net, file.config.design.name())?;
    let json = serde_json::to_vec_pretty(file)?;
    nprt_io::write_file(&dir.join(CONFIG_FILE), &json)
}

/// Weights as safetensors, tagged with the design (or other network kind) that produced them.
pub fn save_weights<M: Module>(path: &Path, net: &M, tag: &str) -> Result<()> {
    // One metadata key only: the header is then byte-for-byte reproducible.
    let mut store = SafetensorsStore::from_bytes(None)
        .clear_metadata()
        .metadata("nprt_design", tag);
    net.save_into(&mut store)
        .map_err(|e| anyhow::anyhow!("cannot serialise weights: {e}"))?;
    let bytes = store
        .get_bytes()
        .map_err(|e| anyhow::anyhow!("cannot serialise weights: {e}"))?;
    nprt_io::write_file(path, &bytes)
}

/// Loads weights saved by [`save_weights`] into `net`, which must be of the same design.
pub fn load_weights<M: Module>(path: &Path, net: &mut M, tag: &str) -> Result<()> {
    let bytes =
        std::fs::read(path).with_context(|| format!("cannot read weights '{}'", path.display()))?;
    let saved_design = read_design_tag(&bytes)
        .with_context(|| format!("'{}' is not an nprt weights file", path.display()))?;
    if saved_design != tag {
        bail!(
            "weights '{}' belong to design '{saved_design}', not '{tag}'",
            path.display()
        );
    }
    let mut store = SafetensorsStore::from_bytes(Some(bytes)).validate(true);
    let result = net
        .load_from(&mut store)
        .map_err(|e| anyhow::anyhow!("cannot load weights '{}': {e}", path.display()))?;
    if !result.errors.is_empty() || !result.missing.is_empty() || !result.unused.is_empty() {
        bail!(
            "weights '{}' do not fit the '{tag}' network: {} missing, {} unexpected, {} bad tensors (first: {})",
            path.display(),
            result.missing.len(),
            result.unused.len(),
            result.errors.len(),
            result
                .missing
                .first()
                .map(|m| m.0.clone())
                .or(result.unused.first().cloned())
                .or(result.errors.first().map(|e| format!("{e:?}")))
                .unwrap_or_default()
        );
    }
    Ok(())
}

/// The `nprt_design` entry of a safetensors header.
fn read_design_tag(bytes: &[u8]) -> Result<String> {
    let (_, metadata) = safetensors::SafeTensors::read_metadata(bytes)
        .map_err(|e| anyhow::anyhow!("not a safetensors file: {e}"))?;
    metadata
        .metadata()
        .as_ref()
        .and_then(|m| m.get("nprt_design"))
        .cloned()
        .context("no nprt_design tag in its metadata")
}

/// Reads a model folder's config, refusing other formats and versions.
pub fn read_model_file(dir: &Path) -> Result<ModelFile> {
    let path = dir.join(CONFIG_FILE);
    let text = std::fs::read_to_string(&path).with_context(|| {
        format!(
            "'{}' is not a model folder (no readable {CONFIG_FILE})",
            dir.display()
        )
    })?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("'{}' is not valid JSON", path.display()))?;
    if value["format"] != MODEL_FORMAT {
        bail!("'{}' is not an nprt model config", path.display());
    }
    if value["version"] != MODEL_VERSION {
        bail!(
            "model '{}' is format version {}, this nprt reads version {MODEL_VERSION}; retrain it with this version",
            dir.display(),
            value["version"]
        );
    }
    serde_json::from_value(value).with_context(|| format!("'{}' is malformed", path.display()))
}

/// Loads a trained model folder onto `device`.
pub fn load_model(dir: &Path, device: &Device) -> Result<(ModelFile, NprtNet)> {
    let file = read_model_file(dir)?;
    let mut net = file.config.build(&mut Init::new(0, device));
    load_weights(&dir.join(WEIGHTS_FILE), &mut net, file.config.design.name())?;
    Ok((file, net))
}

/// Every parameterised layer of a network with its shape and parameter count.
pub fn layer_table(net: &NprtNet) -> Vec<LayerRow> {
    let mut rows = Vec::new();
    for (i, conv) in net.encoder.convs.iter().enumerate() {
        let [o, c, kh, kw] = conv.weight.val().dims();
        rows.push(LayerRow {
            name: format!("encoder.conv{i}"),
            shape: format!("{c}→{o}, {kh}×{kw}"),
            params: conv.num_params(),
        });
    }
    let [i, o] = net.encoder.to_code.weight.val().dims();
    rows.push(LayerRow {
        name: "encoder.to_code".into(),
        shape: format!("{i}→{o}"),
        params: net.encoder.to_code.num_params(),
    });
    for track in &net.tracks {
        let track_name = match net.tracks.len() {
            1 => String::new(),
            _ => format!("{:?}.", track.kind).to_lowercase(),
        };
        if let Some(grid) = &track.grid {
            use crate::hash_grid::{LEVELS, LEVEL_FEATURES, TABLE_SIZE};
            rows.push(LayerRow {
                name: format!("{track_name}grid"),
                shape: format!(
                    "{LEVELS} levels × 2^{} × {LEVEL_FEATURES}",
                    TABLE_SIZE.trailing_zeros()
                ),
                params: grid.num_params(),
            });
        }
        let parts = [
            ("transfer", track.transfer.as_ref()),
            ("shading", Some(&track.shading)),
        ];
        for (part, mlp) in parts {
            let Some(mlp) = mlp else { continue };
            for (l, ([i, o], layer)) in mlp.shapes().into_iter().zip(&mlp.layers).enumerate() {
                let last = l + 1 == mlp.layers.len();
                let act = if last {
                    "linear"
                } else {
                    mlp.activation.name()
                };
                rows.push(LayerRow {
                    name: format!("{track_name}{part}.{l}"),
                    shape: format!("{i}→{o} {act}"),
                    params: layer.num_params(),
                });
            }
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn older_configs_read_as_the_paper_s_and_learned_ones_keep_their_old_form() {
        let old = r#"{"design": "dsep", "activation": "siren", "encoder_width": 128}"#;
        let config: ModelConfig = serde_json::from_str(old).unwrap();
        assert_eq!(config.map_norm, MapNorm::Mean);
        assert_eq!(config.direct, DirectLight::Learned);
        // A learned model's config (and so its run key) has no `direct` field, as before the
        // choice existed; a traced one has it and reads back.
        let json = serde_json::to_value(&config).unwrap();
        assert!(json.get("direct").is_none(), "{json}");
        let traced = ModelConfig {
            direct: DirectLight::Traced,
            ..config
        };
        let json = serde_json::to_string(&traced).unwrap();
        assert!(json.contains(r#""direct":"traced""#), "{json}");
        assert_eq!(serde_json::from_str::<ModelConfig>(&json).unwrap(), traced);
        assert_eq!(traced.label(), "dsep+direct");
        assert!(!json.contains("encoding"), "{json}");
        let grid = ModelConfig {
            encoding: PositionEncoding::HashGrid,
            ..traced
        };
        let json = serde_json::to_string(&grid).unwrap();
        assert!(json.contains(r#""encoding":"hash-grid""#), "{json}");
        assert_eq!(serde_json::from_str::<ModelConfig>(&json).unwrap(), grid);
        assert_eq!(grid.label(), "dsep+grid+direct");
    }
}
