//! The model folder: `model.json` (what to build, how to feed it, where it came from) and the
//! weights, saved and loaded; also the one reader of a folder's versioned JSON config, which
//! Deep Shading's folder shares.

use std::path::Path;

use std::collections::HashMap;

use anyhow::{bail, Context, Result};
use safetensors::{tensor::TensorView, Dtype, SafeTensors};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

pub use nprt_data::dataset::check_bounds;

use crate::init::Init;
use crate::model::config::ModelConfig;
use crate::model::direct_light::DirectLight;
use crate::network::encoder::check_input_width;
use crate::network::nprt_net::NprtNet;
use crate::parameters::Parameters;

/// Identifies a model folder's config file.
pub const MODEL_FORMAT: &str = "nprt-model";
/// Bumped whenever a saved model would be read differently.
pub const MODEL_VERSION: u32 = 1;
pub const CONFIG_FILE: &str = "model.json";
pub const WEIGHTS_FILE: &str = "weights.safetensors";
/// The largest weight a trained network holds, by far (trained weights and hash-grid entries
/// stay within tens): a file with more is damaged, and would render black or infinite frames.
pub const MAX_WEIGHT: f32 = 1e6;

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
    /// level (`nprt train --calibrate level`, training::calibration); absent: as the network says.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub level_gain: Option<[f32; 3]>,
    /// BLAKE3 of the weights file this config was saved with: `model.json` is written last, so
    /// a folder whose weights are not these was cut between its two writes (absent in older
    /// files: not checked).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights_blake3: Option<String>,
}

/// The widest range of a calibrated level gain: calibration measures a few tenths either side
/// of 1 (D/S 1.3-1.6); a gain beyond it would mean a network off by a factor of a thousand,
/// and a file holding one (1e30, 0, −1) rendered, exported and evaluated with exit 0.
pub const LEVEL_GAIN_RANGE: std::ops::RangeInclusive<f32> = 1e-3..=1e3;

impl ModelFile {
    /// The file of an untrained network `net` built from `config`, for a scene with these
    /// bounds: what benchmarks time, whose cost does not depend on the weights.
    pub fn untrained(config: ModelConfig, net: &NprtNet, bounds: [[f32; 3]; 2]) -> Self {
        let transport_params = net.transport_params();
        ModelFile {
            format: MODEL_FORMAT.into(),
            version: MODEL_VERSION,
            config,
            bounds,
            scene: String::new(),
            scene_hash: String::new(),
            dataset_hash: String::new(),
            transport_params,
            encoder_params: net.total_params() - transport_params,
            training: serde_json::Value::Null,
            level_gain: None,
            weights_blake3: None,
        }
    }

    /// What the model is, in one line, `direct` said of a traced direct light (how it is
    /// traced; nothing for a model that learns it): "linear design on sh:2 (siren), direct
    /// light traced (16 spp, denoised by OIDN), level calibrated".
    pub fn describe(&self, direct: &str) -> String {
        let direct = match self.config.direct {
            DirectLight::Traced if !direct.is_empty() => format!(" ({direct})"),
            _ => String::new(),
        };
        let level = match self.level_gain {
            Some(_) => ", level calibrated",
            None => "",
        };
        format!("{}{direct}{level}", self.config.describe())
    }

    /// Seconds of training the model records (None where it records none, or one that is
    /// negative or not finite).
    pub fn trained_seconds(&self) -> Option<f64> {
        (self.training["seconds"].as_f64()).filter(|s| s.is_finite() && *s >= 0.0)
    }

    /// The time budget, minutes, of the run that saved the model (None for a run bounded by
    /// epochs): a run resumes only under the same.
    pub fn run_minutes(&self) -> Option<f64> {
        self.training["options"]["minutes"].as_f64()
    }

    /// The gain on each channel of the network's radiance (1 without calibration).
    pub fn output_gain(&self) -> [f32; 3] {
        self.level_gain.unwrap_or([1.0; 3])
    }
}

/// Writes the weights of `net` and then `model.json`, naming their hash, into `dir`, each file
/// atomically: the config is the marker that the folder is whole ([`load_model`] checks it).
pub fn save_model(dir: &Path, file: &ModelFile, net: &NprtNet) -> Result<()> {
    let hash = save_weights(&dir.join(WEIGHTS_FILE), net, &file.config.weights_tag())?;
    let file = ModelFile {
        weights_blake3: Some(hash),
        ..file.clone()
    };
    let json = serde_json::to_vec_pretty(&file)?;
    nprt_io::write_file(&dir.join(CONFIG_FILE), &json)
}

/// The BLAKE3 of a model folder's weights file, as `model.json` records it.
pub fn weights_hash(dir: &Path) -> Result<String> {
    let path = dir.join(WEIGHTS_FILE);
    let bytes = nprt_io::read_input(&path)
        .with_context(|| format!("cannot read weights '{}'", path.display()))?;
    Ok(hex_hash(&bytes))
}

/// A weights file's bytes as `weights_blake3` records them: BLAKE3, in hex.
fn hex_hash(bytes: &[u8]) -> String {
    blake3::hash(bytes).to_hex().to_string()
}

/// Weights as safetensors, tagged with the network that produced them (`design:activation`,
/// [`ModelConfig::weights_tag`], or another network kind's name). Returns the file's BLAKE3.
pub fn save_weights<M: Parameters>(path: &Path, net: &M, tag: &str) -> Result<String> {
    let mut tensors = Vec::new();
    let mut non_finite = None;
    net.visit("", &mut |name, shape, values| {
        if non_finite.is_none() && !values.iter().all(|v| v.is_finite()) {
            non_finite = Some(name.to_string());
        }
        tensors.push((
            name.to_string(),
            shape.to_vec(),
            bytemuck::cast_slice::<f32, u8>(values).to_vec(),
        ));
    });
    if let Some(name) = non_finite {
        bail!(
            "refusing to write '{}': weight tensor '{name}' holds NaN or infinity (training diverged)",
            path.display()
        );
    }
    let views = tensors
        .iter()
        .map(|(name, shape, bytes)| {
            Ok((
                name.as_str(),
                TensorView::new(Dtype::F32, shape.clone(), bytes)?,
            ))
        })
        .collect::<Result<Vec<_>, safetensors::SafeTensorError>>()?;
    // One metadata key only: the header is then byte-for-byte reproducible.
    let metadata = HashMap::from([("nprt_design".to_string(), tag.to_string())]);
    let bytes = safetensors::serialize(views, Some(metadata))
        .map_err(|e| anyhow::anyhow!("cannot serialise weights: {e}"))?;
    nprt_io::write_file(path, &bytes)?;
    Ok(hex_hash(&bytes))
}

/// The first tensor of a safetensors file that holds a value no trained network has (not
/// finite, or beyond ±[`MAX_WEIGHT`]), and that value, if one does.
fn implausible_tensor(tensors: &SafeTensors) -> Option<(String, f32)> {
    for (name, view) in tensors.tensors() {
        if view.dtype() != safetensors::Dtype::F32 {
            continue;
        }
        let values = view.data().chunks_exact(4);
        let mut values = values.map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        if let Some(v) = values.find(|v| !(v.abs() <= MAX_WEIGHT)) {
            return Some((name, v));
        }
    }
    None
}

/// Loads weights saved by [`save_weights`] into `net`, which must be of the same design.
/// Returns the file's BLAKE3.
pub fn load_weights<M: Parameters>(path: &Path, net: &mut M, tag: &str) -> Result<String> {
    let bytes = nprt_io::read_input(path)
        .with_context(|| format!("cannot read weights '{}'", path.display()))?;
    let saved_design = read_design_tag(&bytes)
        .with_context(|| format!("'{}' is not an nprt weights file", path.display()))?;
    // Weights saved before the tag named the activation carry the design alone.
    let legacy = !saved_design.contains(':') && tag.split(':').next() == Some(&*saved_design);
    if saved_design != tag && !legacy {
        bail!(
            "weights '{}' belong to a '{saved_design}' network, not '{tag}'",
            path.display()
        );
    }
    let file = SafeTensors::deserialize(&bytes)
        .with_context(|| format!("'{}' is not an nprt weights file", path.display()))?;
    if let Some((name, v)) = implausible_tensor(&file) {
        bail!(
            "weights '{}' are unusable: tensor '{name}' holds {v:e}, beyond any trained network's \
             (±{MAX_WEIGHT:e}); the file is damaged",
            path.display()
        );
    }
    let (mut missing, mut bad) = (Vec::new(), Vec::new());
    net.visit_mut("", &mut |name, shape, values| match file.tensor(name) {
        Err(_) => missing.push(name.to_string()),
        Ok(view) if view.dtype() != Dtype::F32 || view.shape() != shape => bad.push(format!(
            "{name} is {:?} {:?}, not F32 {shape:?}",
            view.dtype(),
            view.shape()
        )),
        Ok(view) => {
            for (v, b) in values.iter_mut().zip(view.data().chunks_exact(4)) {
                *v = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
            }
        }
    });
    let mut known = std::collections::HashSet::new();
    net.visit("", &mut |name, _, _| {
        known.insert(name.to_string());
    });
    let unused: Vec<String> = (file.names().into_iter())
        .filter(|n| !known.contains(*n))
        .map(str::to_string)
        .collect();
    if !missing.is_empty() || !unused.is_empty() || !bad.is_empty() {
        bail!(
            "weights '{}' do not fit the '{tag}' network: {} missing, {} unexpected, {} bad tensors (first: {})",
            path.display(),
            missing.len(),
            unused.len(),
            bad.len(),
            missing
                .first()
                .or(unused.first())
                .or(bad.first())
                .cloned()
                .unwrap_or_default()
        );
    }
    Ok(hex_hash(&bytes))
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

/// Reads a model folder's config, refusing other formats and versions, sizes no network can
/// have (an edited encoder_width would allocate without bound) or this machine cannot hold, and
/// a level gain no calibration makes: every reader of a model folder comes through here.
pub fn read_model_file(dir: &Path) -> Result<ModelFile> {
    let file: ModelFile = read_config(dir, CONFIG_FILE, MODEL_FORMAT, MODEL_VERSION, "model")?;
    check_input_width(file.config.encoder_width)
        .and_then(|()| file.config.check())
        .and_then(|()| check_bounds(&file.bounds))
        .and_then(|()| check_level_gain(file.level_gain))
        .and_then(|()| file.config.ensure_memory(1, "its network"))
        .with_context(|| format!("model '{}'", dir.display()))?;
    Ok(file)
}

/// Refuses a level gain outside [`LEVEL_GAIN_RANGE`] (NaN included), naming the channel.
fn check_level_gain(gain: Option<[f32; 3]>) -> Result<()> {
    let channels = gain
        .iter()
        .flat_map(|g| ["R", "G", "B"].into_iter().zip(*g));
    for (channel, g) in channels {
        if !LEVEL_GAIN_RANGE.contains(&g) {
            bail!(
                "its level_gain's {channel} is {}, outside the {} to {} a calibration \
                 measures; the file is damaged (remove level_gain to render uncalibrated)",
                nprt_io::short_number(g),
                LEVEL_GAIN_RANGE.start(),
                LEVEL_GAIN_RANGE.end()
            );
        }
    }
    Ok(())
}

/// Reads the versioned JSON config `file_name` of a folder of `kind` ("model", "Deep Shading
/// model"): errors name the folder or file and say whether it is missing, not JSON, another
/// format, another version or malformed.
pub fn read_config<T: DeserializeOwned>(
    dir: &Path,
    file_name: &str,
    format: &str,
    version: u32,
    kind: &str,
) -> Result<T> {
    let path = dir.join(file_name);
    let text = nprt_io::read_input_string(&path).with_context(|| {
        format!(
            "'{}' is not a {kind} folder (no readable {file_name})",
            dir.display()
        )
    })?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("'{}' is not valid JSON", path.display()))?;
    if value["format"] != format {
        bail!("'{}' is not an nprt {kind} config", path.display());
    }
    if value["version"] != version {
        bail!(
            "{kind} '{}' is format version {}, this nprt reads version {version}; retrain it with this version",
            dir.display(),
            value["version"]
        );
    }
    serde_json::from_value(value).with_context(|| format!("'{}' is malformed", path.display()))
}

/// Refuses a model folder whose weights (BLAKE3 `hash`) are not the ones its config
/// `config_file` was saved with (`saved`; none in files from before it was recorded): the
/// config is written last, so the folder was cut between its two writes, or edited.
pub fn check_whole(dir: &Path, config_file: &str, saved: Option<&str>, hash: &str) -> Result<()> {
    if let Some(saved) = saved.filter(|s| *s != hash) {
        bail!(
            "model '{}' is incomplete: its {WEIGHTS_FILE} (BLAKE3 {}…) is not the one {config_file} \
             was saved with ({}…), as when a save is cut between its two files; run the training \
             again to save it whole",
            dir.display(),
            &hash[..12],
            saved.get(..12).unwrap_or(saved)
        );
    }
    Ok(())
}

/// Loads a trained model folder.
pub fn load_model(dir: &Path) -> Result<(ModelFile, NprtNet)> {
    let file = read_model_file(dir)?;
    let mut net = file.config.build(&mut Init::new(0));
    let hash = load_weights(
        &dir.join(WEIGHTS_FILE),
        &mut net,
        &file.config.weights_tag(),
    )?;
    let counts = [
        net.transport_params(),
        net.total_params() - net.transport_params(),
    ];
    if [file.transport_params, file.encoder_params] != counts {
        bail!(
            "model '{}': its {CONFIG_FILE} counts {} transport and {} encoder parameters, its \
             network has {} and {}; the file is damaged",
            dir.display(),
            file.transport_params,
            file.encoder_params,
            counts[0],
            counts[1]
        );
    }
    check_whole(dir, CONFIG_FILE, file.weights_blake3.as_deref(), &hash)?;
    Ok((file, net))
}
