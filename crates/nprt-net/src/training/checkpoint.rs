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
    if let Some(problem) = problem(&ck) {
        bail!(
            "checkpoint '{}' is damaged: {problem}; delete the model folder to start over",
            path.display()
        );
    }
    Ok(Some(ck))
}

/// What no run writes into its state file, if `ck` holds it: the one check of a checkpoint,
/// made as it is read. A training time negative or not finite let a run train past its budget
/// (or never start); an epoch or batch beyond the steps (every epoch and batch is a step, every
/// step at least one sample: an epoch of 10⁹ after a few steps replayed a billion epochs'
/// shuffles before the first step); a history row no run writes; file names that are not this
/// folder's own (a name with a path in it would be read from elsewhere).
fn problem(ck: &Checkpoint) -> Option<String> {
    let s = &ck.state;
    if !(s.seconds.is_finite() && s.seconds >= 0.0) {
        return Some(format!(
            "it says the run has trained {} s",
            nprt_io::short_number(s.seconds)
        ));
    }
    if s.epoch as u64 > s.step || s.batch as u64 > s.step || s.samples < s.step {
        return Some(format!(
            "it says {} epochs, batch {}, {} steps and {} samples",
            s.epoch, s.batch, s.step, s.samples
        ));
    }
    if let Some((i, p)) =
        (ck.history.iter().enumerate()).find_map(|(i, r)| r.problem().map(|p| (i, p)))
    {
        return Some(format!("its history's row {}: {p}", i + 1));
    }
    let own = |name: &str, ok: bool| {
        (!ok || name.contains(['/', '\\']) || name.starts_with('.'))
            .then(|| format!("it names '{name}', not a file of its own folder"))
    };
    own(
        &ck.weights,
        ck.weights.starts_with("weights-") && ck.weights.ends_with(".safetensors"),
    )
    .or_else(|| own(&ck.optimizer, is_state_file(&ck.optimizer)))
}

/// Where a run stands and its last validation loss, as its checkpoint in the model folder
/// `out` says (checked as every reader of a checkpoint checks it); none without a checkpoint.
pub fn progress(out: &Path) -> Result<Option<(RunState, Option<f64>)>> {
    Ok(read(out)?.map(|ck| {
        let val = ck.history.iter().rev().find_map(|r| r.val);
        (ck.state, val)
    }))
}

/// Loads the checkpoint's weights into `net`.
pub(crate) fn restore_weights<M: Parameters>(
    out: &Path,
    ck: &Checkpoint,
    net: &mut M,
    tag: &str,
) -> Result<()> {
    load_weights(&dir(out).join(&ck.weights), net, tag).map(drop)
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

    /// `nprt generate` refuses a model folder by these names, stated in nprt-data.
    #[test]
    fn the_dataset_s_list_of_model_entries_names_every_file_a_run_writes() {
        let written = [
            DIR,
            crate::model::folder::CONFIG_FILE,
            crate::model::folder::WEIGHTS_FILE,
            crate::deep_shading::CONFIG_FILE,
        ];
        for name in written {
            assert!(
                nprt_data::dataset::MODEL_FOLDER_ENTRIES.contains(&name),
                "{name}"
            );
        }
    }

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
            weights: "weights-000000000.safetensors".into(),
            optimizer: state_file(0),
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
