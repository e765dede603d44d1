//! A run's resumable state in `checkpoint/` of its model folder, the same for every network:
//! the weights, Adam's moments and `state.json`, which names them and is written last
//! (atomically), so it never names files that do not exist.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use burn::module::Module;
use burn::optim::ModuleOptimizer;
use serde::{Deserialize, Serialize};

use crate::curves::LossRow;
use crate::model::{load_weights, save_weights};

const DIR: &str = "checkpoint";
const STATE_FILE: &str = "state.json";

/// Where a run stands.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct RunState {
    /// Epochs finished.
    pub epoch: usize,
    /// Next batch within `epoch`.
    pub batch: usize,
    pub step: u64,
    pub samples: u64,
    pub seconds: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub(crate) struct Checkpoint {
    /// All that shapes the run; a checkpoint resumes only under an equal one.
    pub run: serde_json::Value,
    #[serde(flatten)]
    pub state: RunState,
    pub history: Vec<LossRow>,
    pub weights: String,
    pub optimizer: String,
}

pub(crate) fn dir(out: &Path) -> PathBuf {
    out.join(DIR)
}

/// Whether `out` holds a checkpoint (the state file is written last).
pub(crate) fn exists(out: &Path) -> bool {
    dir(out).join(STATE_FILE).exists()
}

pub(crate) fn read(out: &Path) -> Result<Option<Checkpoint>> {
    let path = dir(out).join(STATE_FILE);
    if !path.exists() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read checkpoint '{}'", path.display()))?;
    let ck = serde_json::from_str(&text).with_context(|| {
        format!(
            "checkpoint '{}' is malformed (or from an older nprt); delete the folder to start over",
            path.display()
        )
    })?;
    Ok(Some(ck))
}

/// Loads the checkpoint's weights into `net` and its optimiser state.
pub(crate) fn restore<M: Module>(
    out: &Path,
    ck: &Checkpoint,
    net: &mut M,
    optim: ModuleOptimizer,
    tag: &str,
) -> Result<ModuleOptimizer> {
    let dir = dir(out);
    load_weights(&dir.join(&ck.weights), net, tag)?;
    if let Some(device) = net.devices().into_iter().next() {
        crate::compute::make_default(&device);
    }
    optim
        .load(dir.join(&ck.optimizer))
        .map_err(|e| anyhow::anyhow!("cannot read optimiser state in '{}': {e:?}", dir.display()))
}

/// Weights, optimiser state, then the state file that names them; older files are removed last.
pub(crate) fn write<M: Module>(
    out: &Path,
    ck: &mut Checkpoint,
    net: &M,
    optim: &ModuleOptimizer,
    tag: &str,
) -> Result<()> {
    let dir = dir(out);
    let weights = format!("weights-{:09}.safetensors", ck.state.step);
    let optimizer = format!("optimizer-{:09}.bpk", ck.state.step);
    save_weights(&dir.join(&weights), net, tag)?;
    optim.save(dir.join(&optimizer)).map_err(|e| {
        anyhow::anyhow!("cannot write optimiser state in '{}': {e:?}", dir.display())
    })?;
    ck.weights = weights;
    ck.optimizer = optimizer;
    let json = serde_json::to_vec_pretty(ck)?;
    nprt_io::write_file(&dir.join(STATE_FILE), &json)?;
    for entry in std::fs::read_dir(&dir)?.flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        if (name.starts_with("weights-") || name.starts_with("optimizer-"))
            && name != ck.weights
            && name != ck.optimizer
        {
            std::fs::remove_file(entry.path()).ok();
        }
    }
    Ok(())
}
