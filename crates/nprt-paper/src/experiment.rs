//! One experiment: a scene and its lightings at a budget, through every stage (dataset, the
//! designs and Table 2's ablation, Deep Shading, the evaluation against every baseline, the
//! paper's tables, a relit camera path), in one output folder that a repeated run resumes.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use nprt_data::CameraChoice;
use nprt_eval::{Evaluation, MethodResult};
use nprt_net::{Design, DirectLight, Engine, ModelConfig};
use serde_json::json;

use crate::budget::{Budget, DEMO, TINY};
use crate::orderings::ablation_configs;
use crate::paper_report::write_paper_report;
use crate::stage_log::StageLog;
use crate::stages;

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
}

/// What a run produced.
pub struct Outcome {
    pub evaluation: Evaluation,
    /// Table 2's four runs on the test views (empty without the paper's tables).
    pub ablation: Vec<MethodResult>,
    /// The evaluation's report.html.
    pub report: PathBuf,
    /// The paper's tables, paper.md and paper.html.
    pub paper: Option<(PathBuf, PathBuf)>,
    pub relit: Option<PathBuf>,
    pub seconds: f64,
}

impl Experiment {
    /// `nprt paper`: the paper's four designs, Table 2's ablation, every baseline and the tables.
    pub fn paper(scene: &str, envmaps: &str, out: &Path, budget: Budget, engine: Engine) -> Self {
        Experiment {
            scene: scene.into(),
            envmaps: envmaps.into(),
            out: out.into(),
            budget,
            camera: CameraChoice::default(),
            test_maps: None,
            seed: 0,
            designs: Design::ALL.map(|d| ModelConfig::new(d, None)).to_vec(),
            paper_tables: true,
            relight: false,
            engine,
        }
    }

    /// `nprt demo`: builtin:room under built-in lighting, the four designs and D/S with its
    /// direct light traced at run time (the paper's suggested extension, docs/model.md), every
    /// baseline, and a relit camera path; `quick` at the tiny budget.
    pub fn demo(out: &Path, quick: bool, engine: Engine) -> Self {
        let mut designs = Design::ALL.map(|d| ModelConfig::new(d, None)).to_vec();
        designs.push(ModelConfig {
            direct: DirectLight::Traced,
            ..ModelConfig::new(Design::Dsep, None)
        });
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

    fn model_dir(&self, config: &ModelConfig) -> PathBuf {
        self.out.join("models").join(config.label())
    }

    /// Runs every stage not already done, in order.
    pub fn run(&self) -> Result<Outcome> {
        std::fs::create_dir_all(&self.out)
            .with_context(|| format!("cannot create '{}'", self.out.display()))?;
        self.claim_folder()?;
        let mut log = StageLog::open(&self.out)?;
        let data = self.out.join("dataset");
        log.begin(
            "dataset",
            &format!(
                "generating the dataset: {} under {} maps",
                self.scene, self.envmaps
            ),
        );
        let worked = stages::dataset(self, &data)?;
        log.end(worked)?;
        let models = self.models();
        for (i, config) in models.iter().enumerate() {
            let name = format!("train {}", config.label());
            log.begin(
                &name,
                &format!(
                    "training model {} of {}: {}",
                    i + 1,
                    models.len(),
                    config.label()
                ),
            );
            let worked = stages::train_model(self, &data, config, &self.model_dir(config))?;
            log.end(worked)?;
        }
        let deep = self.out.join("models").join("deep-shading");
        log.begin("train deep-shading", "training the Deep Shading baseline");
        let worked = stages::train_deep_shading(self, &data, &deep)?;
        log.end(worked)?;

        log.begin("evaluation", "evaluating against the baselines");
        let report = self.out.join("report");
        let dirs: Vec<PathBuf> = self.designs.iter().map(|c| self.model_dir(c)).collect();
        let opts = nprt_eval::EvalOptions {
            deep_shading: Some(deep),
            ..stages::eval_options(self, &data, &dirs)
        };
        let (evaluation, worked) = stages::evaluation(self, &opts, &report)?;
        log.end(worked)?;

        let (mut ablation, mut paper) = (Vec::new(), None);
        if self.paper_tables {
            log.begin("table 2", "scoring Table 2's ablation on the test views");
            let dirs: Vec<PathBuf> = ablation_configs()
                .iter()
                .map(|c| self.model_dir(c))
                .collect();
            let opts = stages::eval_options(self, &data, &dirs);
            let (rows, worked) = stages::ablation(self, &opts, &report.join("table2.json"))?;
            log.end(worked)?;
            ablation = rows;
            paper = Some(write_paper_report(
                self,
                &evaluation,
                &ablation,
                &log.times,
                &report,
            )?);
        }
        let mut relit = None;
        if self.relight {
            log.begin(
                "relight",
                "relighting a camera path under held-out lighting",
            );
            let frames = self.out.join("relit");
            let last = self
                .designs
                .last()
                .context("an experiment trains a design")?;
            stages::relight(self, &data, &self.model_dir(last), &frames)?;
            log.end(true)?;
            relit = Some(frames);
        }
        Ok(Outcome {
            evaluation,
            ablation,
            report: report.join("report.html"),
            paper,
            relit,
            seconds: log.elapsed(),
        })
    }

    /// What the output folder is for, written on its first run: a later run with another
    /// scene, lighting, budget or seed is refused rather than mixed into it.
    fn claim_folder(&self) -> Result<()> {
        let what = json!({
            "scene": self.scene,
            "envmaps": self.envmaps,
            "budget": self.budget.name,
            "seed": self.seed,
            "test_maps": self.test_maps,
            "camera_volume": self.camera.file,
            "models": self.models().iter().map(|c| c.label()).collect::<Vec<_>>(),
        });
        let file = self.out.join("experiment.json");
        if let Ok(bytes) = std::fs::read(&file) {
            let before: serde_json::Value = serde_json::from_slice(&bytes)
                .with_context(|| format!("'{}' is not an experiment record", file.display()))?;
            if before != what {
                bail!(
                    "'{}' holds another experiment ({}); this one is {}: give another output folder, or remove it to start again",
                    self.out.display(),
                    before,
                    what
                );
            }
            return Ok(());
        }
        nprt_io::write_file(&file, serde_json::to_vec_pretty(&what)?)
    }
}
