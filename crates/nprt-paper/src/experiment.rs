//! One experiment: a scene and its lightings at a budget, the models it trains and what it
//! writes, in one output folder (its stages run in `pipeline`).

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use nprt_data::{CameraChoice, GenerateOptions, ViewSpec};
use nprt_net::training::snapshot::Snapshot;
use nprt_net::{Calibration, Design, DirectLight, Engine, ModelConfig, RunLength, RECIPE};

use crate::budget::{Budget, DEMO, TINY};
use crate::orderings::ablation_configs;

/// What to run.
#[derive(Clone, Debug)]
pub struct Experiment {
    /// `builtin:room`, or a Mitsuba .xml / glTF / mesh file.
    pub scene: String,
    /// A folder of lat-long maps, or `builtin`.
    pub envmaps: String,
    pub out: PathBuf,
    pub budget: Budget,
    /// Where the dataset's cameras go (default: the scene's camera volume).
    pub camera: CameraChoice,
    /// Maps of a folder held out for the test views (default: a fifth).
    pub test_maps: Option<usize>,
    pub seed: u64,
    /// Models trained and evaluated against every baseline (Table 5's designs first).
    pub designs: Vec<ModelConfig>,
    /// Also train Table 2's ablation and write the paper's tables.
    pub paper_tables: bool,
    /// Also relight a camera path under the held-out maps with the last design.
    pub relight: bool,
    pub engine: Engine,
    /// Points at which the paper's four designs keep their models as they train, each scored
    /// on the test views and judged by the paper's orderings (`--snapshots`).
    pub snapshots: Vec<Snapshot>,
    /// Every network's training in wall-clock minutes instead of the budget's
    /// (`--training-minutes`): the budget's sizes with longer training, recorded with the
    /// experiment.
    pub training_minutes: Option<f64>,
}

/// The design beyond the paper that `nprt paper` and `nprt demo` set beside D/S in Table 6:
/// the recommended recipe's (`nprt_net::RECIPE`: the linear design on spherical harmonics to
/// band 2, its direct light traced; docs/model.md, "The recommended recipe").
pub fn beyond_the_paper() -> ModelConfig {
    RECIPE.config()
}

/// How a design's saved output is calibrated: the recipe's model as the recipe says (its level
/// set from its training targets, `nprt train --calibrate level`); the paper's designs keep
/// their raw output.
pub fn calibration(config: &ModelConfig) -> Calibration {
    if *config == RECIPE.config() {
        RECIPE.calibration
    } else {
        Calibration::None
    }
}

/// The paper's four designs with their own settings, then the design beyond them.
fn paper_designs() -> Vec<ModelConfig> {
    let mut designs = Design::PAPER.map(|d| ModelConfig::new(d, None)).to_vec();
    designs.push(beyond_the_paper());
    designs
}

impl Experiment {
    /// `nprt paper`: the paper's four designs and the linear design beyond them, Table 2's
    /// ablation, every baseline and the tables.
    pub fn paper(scene: &str, envmaps: &str, out: &Path, budget: Budget, engine: Engine) -> Self {
        Experiment {
            scene: scene.into(),
            envmaps: envmaps.into(),
            out: out.into(),
            budget,
            camera: CameraChoice::default(),
            test_maps: None,
            seed: 0,
            designs: paper_designs(),
            paper_tables: true,
            relight: false,
            engine,
            snapshots: Vec::new(),
            training_minutes: None,
        }
    }

    /// `nprt demo`: builtin:room under built-in lighting, the four designs, D/S with its
    /// direct light traced at run time (the paper's suggested extension, docs/model.md) and the
    /// linear design beyond them, every baseline, and a camera path relit by the last.
    /// `quick` at the tiny budget.
    pub fn demo(out: &Path, quick: bool, engine: Engine) -> Self {
        let mut designs = paper_designs();
        designs.insert(
            Design::PAPER.len(),
            ModelConfig {
                direct: DirectLight::Traced,
                ..ModelConfig::new(Design::Dsep, None)
            },
        );
        Experiment {
            designs,
            paper_tables: false,
            relight: true,
            ..Experiment::paper(
                "builtin:room",
                "builtin",
                out,
                if quick { TINY } else { DEMO },
                engine,
            )
        }
    }

    /// The models that keep snapshots: the paper's four designs with their own settings.
    pub fn snapshot_configs(&self) -> Vec<ModelConfig> {
        let paper = Design::PAPER.map(|d| ModelConfig::new(d, None));
        self.designs
            .iter()
            .filter(|c| paper.contains(c))
            .cloned()
            .collect()
    }

    /// Every Neural PRT model to train: the designs, then the ablation's runs not among them.
    pub fn models(&self) -> Vec<ModelConfig> {
        let mut all = self.designs.clone();
        if self.paper_tables {
            for c in ablation_configs() {
                if !all.contains(&c) {
                    all.push(c);
                }
            }
        }
        all
    }

    /// The dataset this experiment renders into `data`.
    pub fn generate_options(&self, data: &Path) -> GenerateOptions {
        let b = &self.budget;
        GenerateOptions {
            scene: self.scene.clone(),
            envmaps: self.envmaps.clone(),
            out: data.to_path_buf(),
            views: ViewSpec {
                train_views: b.train_views,
                test_views: b.test_views,
                train_resolution: [b.train_res; 2],
                test_resolution: [b.test_res; 2],
                spp: b.spp,
                test_spp: b.test_spp,
                seed: self.seed,
                ..ViewSpec::default()
            },
            test_maps: self.test_maps,
            camera: self.camera.clone(),
            device: self.engine.tracer(),
            progress: true,
            ..GenerateOptions::default()
        }
    }

    /// Each Neural PRT network's training: the budget's, or `training_minutes`.
    pub fn training(&self) -> RunLength {
        self.training_minutes
            .map_or(self.budget.training, RunLength::minutes)
    }

    /// Deep Shading's training: the budget's, or `training_minutes` (equal cost with the designs).
    pub fn deep_shading_training(&self) -> RunLength {
        self.training_minutes
            .map_or(self.budget.deep_shading, RunLength::minutes)
    }

    /// Refuses, before any work, paths that are not UTF-8 (the experiment writes them into its
    /// records, the report and `nprt generate`'s flags, which would hold another path) and a
    /// training time outside [`nprt_net::check_minutes`]'s range, naming the flag.
    pub fn check_settings(&self) -> Result<()> {
        if let Some(m) = self.training_minutes {
            nprt_net::check_minutes(m, "--training-minutes").map_err(anyhow::Error::msg)?;
        }
        let paths = [
            ("--out", Some(&self.out)),
            ("--camera-volume", self.camera.file.as_ref()),
        ];
        for (flag, path) in paths {
            if let Some(p) = path.filter(|p| p.to_str().is_none()) {
                bail!(
                    "{flag} '{}' is not valid UTF-8: nprt paper writes its paths into its \
                     records and flags; use a path of UTF-8 characters",
                    p.display()
                );
            }
        }
        Ok(())
    }

    /// The `nprt generate` flags that render this experiment's dataset (into `OUT/dataset`),
    /// for a cluster to render it first (`scripts/slurm-generate N -- FLAGS`, docs/paper.md);
    /// a run then finds it complete.
    pub fn generate_flags(&self) -> Result<Vec<String>> {
        self.check_settings()?;
        let o = self.generate_options(&self.dataset_dir());
        let mut flags: Vec<String> = [
            ("--scene", o.scene.clone()),
            ("--envmaps", o.envmaps.clone()),
            ("--out", o.out.display().to_string()),
            ("--train-views", o.views.train_views.to_string()),
            ("--test-views", o.views.test_views.to_string()),
            ("--train-res", o.views.train_resolution[0].to_string()),
            ("--test-res", o.views.test_resolution[0].to_string()),
            ("--spp", o.views.spp.to_string()),
            ("--test-spp", o.views.test_spp.to_string()),
            ("--seed", o.views.seed.to_string()),
        ]
        .into_iter()
        .flat_map(|(k, v)| [k.to_string(), v])
        .collect();
        if let Some(n) = o.test_maps {
            flags.extend(["--test-maps".into(), n.to_string()]);
        }
        if let Some(f) = &o.camera.file {
            flags.extend(["--camera-volume".into(), f.display().to_string()]);
        }
        Ok(flags)
    }

    pub(crate) fn dataset_dir(&self) -> PathBuf {
        self.out.join("dataset")
    }

    pub(crate) fn model_dir(&self, config: &ModelConfig) -> PathBuf {
        self.out.join("models").join(config.label())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::budget::SMALL;

    #[test]
    fn training_minutes_replace_the_budgets_training_for_every_network() {
        let mut x = Experiment::paper(
            "builtin:room",
            "builtin",
            Path::new("o"),
            SMALL,
            Engine::Cpu,
        );
        assert_eq!(x.training(), SMALL.training);
        assert_eq!(x.deep_shading_training(), SMALL.deep_shading);
        x.training_minutes = Some(16.0);
        assert_eq!(x.training(), RunLength::minutes(16.0));
        assert_eq!(x.deep_shading_training(), RunLength::minutes(16.0));
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e-320, 1e300] {
            x.training_minutes = Some(bad);
            let err = x.check_settings().unwrap_err().to_string();
            assert!(err.contains("--training-minutes"), "{err}");
        }
    }
}
