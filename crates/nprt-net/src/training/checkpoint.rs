//! A run's resumable state in `checkpoint/` of its model folder, the same for every network:
//! the weights, Adam's moments and `state.json`, which names them and is written last
//! (atomically), so it never names files that do not exist.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

use crate::model::folder::{load_weights, save_weights};
use crate::optimiser::{is_state_file, state_file, EngineSteps};
use crate::parameters::Parameters;
use crate::training::loss_curves::LossRow;

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
pub fn exists(out: &Path) -> bool {
    dir(out).join(STATE_FILE).exists()
}

pub(crate) fn read(out: &Path) -> Result<Option<Checkpoint>> {
    let path = dir(out).join(STATE_FILE);
    if !path.exists() {
        return Ok(None);
    }
    let text = nprt_io::read_input_string(&path)
        .with_context(|| format!("cannot read checkpoint '{}'", path.display()))?;
    let ck: Checkpoint = serde_json::from_str(&text).with_context(|| {
        format!(
            "checkpoint '{}' is malformed (or from an older nprt); delete the folder to start over",
            path.display()
        )
    })?;
    // Read back as input: a training time that is negative or not finite would let a run
    // train past its budget (or never start).
    let seconds = ck.state.seconds;
    if !(seconds.is_finite() && seconds >= 0.0) {
        bail!(
            "checkpoint '{}' says the run has trained {seconds} s, which no run has; delete \
             the folder to start over",
            path.display()
        );
    }
    Ok(Some(ck))
}

/// Loads the checkpoint's weights into `net`.
pub(crate) fn restore_weights<M: Parameters>(
    out: &Path,
    ck: &Checkpoint,
    net: &mut M,
    tag: &str,
) -> Result<()> {
    load_weights(&dir(out).join(&ck.weights), net, tag)
}

/// Loads the checkpoint's optimiser state into `steps`.
pub(crate) fn restore_optimiser<M, B>(
    out: &Path,
    ck: &Checkpoint,
    steps: &mut dyn EngineSteps<M, B>,
) -> Result<()> {
    steps.load(&dir(out).join(&ck.optimizer))
}

/// Weights, optimiser state, then the state file that names them; older files are removed last.
pub(crate) fn write<M: Parameters, B>(
    out: &Path,
    ck: &mut Checkpoint,
    net: &M,
    steps: &dyn EngineSteps<M, B>,
    tag: &str,
) -> Result<()> {
    let dir = dir(out);
    let weights = format!("weights-{:09}.safetensors", ck.state.step);
    let optimizer = state_file(ck.state.step);
    save_weights(&dir.join(&weights), net, tag)?;
    steps.save(&dir.join(&optimizer))?;
    ck.weights = weights;
    ck.optimizer = optimizer;
    let json = serde_json::to_vec_pretty(ck)?;
    nprt_io::write_file(&dir.join(STATE_FILE), &json)?;
    for entry in std::fs::read_dir(&dir)?.flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        if (name.starts_with("weights-") || is_state_file(&name))
            && name != ck.weights
            && name != ck.optimizer
        {
            std::fs::remove_file(entry.path()).ok();
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// A resumed run carries its history on, so every loss must come back bit for bit (the
    /// default JSON float parser is off by an ulp on some values, such as the first below).
    #[test]
    fn the_history_survives_the_state_file_exactly() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        let mut values = vec![0.015105420413116612, 1e-300, 1e300, 5e-324];
        values.extend(
            (0..20_000).map(|_| rng.random::<f64>() * 10f64.powi(rng.random_range(-12..4))),
        );
        let history: Vec<LossRow> = values
            .iter()
            .enumerate()
            .map(|(i, &v)| LossRow {
                step: i as u64,
                epoch: v * 3.0,
                samples: i as u64,
                seconds: v / 7.0,
                train: Some(v),
                val: (i % 2 == 0).then_some(v.sqrt()),
            })
            .collect();
        let ck = Checkpoint {
            run: serde_json::json!({ "lr": values[0] }),
            state: RunState::default(),
            history: history.clone(),
            weights: "w".into(),
            optimizer: "o".into(),
        };
        let out = std::env::temp_dir().join(format!("nprt-ck-{}", std::process::id()));
        std::fs::create_dir_all(dir(&out)).unwrap();
        nprt_io::write_file(
            &dir(&out).join(STATE_FILE),
            serde_json::to_vec_pretty(&ck).unwrap(),
        )
        .unwrap();
        let back = read(&out).unwrap().unwrap();
        std::fs::remove_dir_all(&out).ok();
        assert_eq!(back.run, ck.run);
        let bits = |r: &LossRow| {
            [Some(r.epoch), Some(r.seconds), r.train, r.val].map(|v| v.map(f64::to_bits))
        };
        for (a, b) in history.iter().zip(&back.history) {
            assert_eq!(bits(a), bits(b), "row {}", a.step);
        }
    }
}
