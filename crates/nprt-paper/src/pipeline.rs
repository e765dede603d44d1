//! An experiment run through every stage (dataset, the designs and Table 2's ablation, Deep
//! Shading, the evaluation against every baseline, the paper's tables, a relit camera path), in
//! one output folder that a repeated run resumes.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use nprt_eval::{Evaluation, MethodResult};
use serde_json::json;

use crate::claim::Claim;
use crate::experiment::Experiment;
use crate::orderings::ablation_configs;
use crate::paper_report::write_paper_report;
use crate::stage_log::StageLog;
use crate::stages;

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
    /// Runs every stage not already done, in order.
    pub fn run(&self) -> Result<Outcome> {
        self.check_settings()?;
        std::fs::create_dir_all(&self.out)
            .with_context(|| format!("cannot create '{}'", self.out.display()))?;
        let _lock = nprt_io::lock_folder(&self.out, "experiment folder", "--out")?;
        let claim = self.claim()?;
        let mut log = StageLog::open(&self.out)?;
        let data = self.dataset_dir();
        log.begin(
            "dataset",
            &format!(
                "generating the dataset: {} under {} maps",
                self.scene, self.envmaps
            ),
        );
        let worked = stages::dataset(self, &data)?;
        log.end(worked)?;
        // Claimed once the dataset stage has taken the settings: a run they are refused in
        // leaves the folder free for the corrected command.
        if let Some(claim) = claim {
            claim.write()?;
        }
        let deep = self.train_models(&mut log, &data)?;

        log.begin("evaluation", "evaluating against the baselines");
        let report = self.out.join("report");
        let dirs: Vec<PathBuf> = self.designs.iter().map(|c| self.model_dir(c)).collect();
        let opts = nprt_eval::EvalOptions {
            deep_shading: Some(deep),
            ..stages::eval_options(self, &data, &dirs)
        };
        let (evaluation, worked) = stages::evaluation(self.engine, &opts, &report)?;
        log.end(worked)?;

        let (ablation, paper) = match self.paper_tables {
            true => {
                let (ablation, paper) = self.paper_tables(&mut log, &data, &report, &evaluation)?;
                (ablation, Some(paper))
            }
            false => (Vec::new(), None),
        };
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

    /// The training stages: each design's model, then the Deep Shading baseline, whose
    /// folder it returns.
    fn train_models(&self, log: &mut StageLog, data: &Path) -> Result<PathBuf> {
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
            let worked = stages::train_model(self, data, config, &self.model_dir(config))?;
            log.end(worked)?;
        }
        let deep = self.out.join("models").join("deep-shading");
        log.begin("train deep-shading", "training the Deep Shading baseline");
        let worked = stages::train_deep_shading(self, data, &deep)?;
        log.end(worked)?;
        Ok(deep)
    }

    /// Table 2's ablation scored, the snapshots scored (`--snapshots`), and the paper's tables
    /// written into `report` beside the evaluation `e`.
    fn paper_tables(
        &self,
        log: &mut StageLog,
        data: &Path,
        report: &Path,
        e: &Evaluation,
    ) -> Result<(Vec<MethodResult>, (PathBuf, PathBuf))> {
        log.begin("table 2", "scoring Table 2's ablation on the test views");
        let dirs: Vec<PathBuf> = ablation_configs()
            .iter()
            .map(|c| self.model_dir(c))
            .collect();
        let opts = stages::eval_options(self, data, &dirs);
        let (ablation, worked) = stages::ablation(self, &opts, &report.join("table2.json"))?;
        log.end(worked)?;
        let mut growth = Vec::new();
        if !self.snapshots.is_empty() {
            log.begin(
                "snapshots",
                "scoring the four designs as kept at each snapshot point",
            );
            let (points, worked) = stages::snapshots(self, data, &report.join("snapshots.json"))?;
            log.end(worked)?;
            growth = points;
        }
        let paper = write_paper_report(self, e, (&ablation, &growth), &log.times, report)?;
        Ok((ablation, paper))
    }

    /// What the output folder is for, recorded by its first run once its settings hold: a
    /// later run with another scene, lighting, budget, training time or seed is refused rather
    /// than mixed into it.
    fn claim(&self) -> Result<Option<Claim>> {
        let mut what = json!({
            "scene": self.scene,
            "envmaps": self.envmaps,
            "budget": self.budget.name,
            "seed": self.seed,
            "test_maps": self.test_maps,
            "camera_volume": self.camera.file,
            "models": self.models().iter().map(|c| c.label()).collect::<Vec<_>>(),
        });
        // Only where given, so that folders recorded before the flag existed still resume.
        if let Some(m) = self.training_minutes {
            what["training_minutes"] = json!(m);
        }
        Claim::check(&self.out, "experiment.json", "experiment", what)
    }
}
