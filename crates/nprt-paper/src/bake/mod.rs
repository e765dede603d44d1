//! `nprt bake`: a scene and its lightings to a relit model in one resumable command. The
//! dataset the recommended recipe needs (`nprt_net::RECIPE`), sized by `--quality` and the
//! scene's bounds; the recipe trained, with a first relit frame written after its first
//! minutes; a short check against path tracing of equal cost on held-out views; one progress
//! bar over it all, its ETA from the rates the stages measure. A killed run resumes where it
//! stopped (each stage resumes itself, the check is cached by its inputs); another bake into
//! the same folder is refused.

mod comparison;
pub mod quality;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use nprt_data::{generate, CameraChoice, GenerateOptions, ViewSpec};
use nprt_eval::{row_name, EvalOptions, Evaluation, MethodResult};
use nprt_net::training::training_set::TrainingSet;
use nprt_net::{Engine, ModelConfig, RunLength, TrainOptions, RECIPE};
use nprt_render::{CameraPath, Denoise, DenoiseCheck};
use nprt_trace::{render, PixelFilter, RenderSettings, TraceScene};
use serde_json::json;

pub use comparison::write_comparison;
pub use quality::{Quality, Sizes};

use crate::claim::Claim;
use crate::stages;

/// One bake: what to bake, where, how big.
#[derive(Clone, Debug)]
pub struct Bake {
    /// `builtin:room`, or a Mitsuba .xml / glTF / mesh file with a camera volume.
    pub scene: String,
    /// A folder of lat-long maps (some held out for the check), or `builtin`.
    pub envmaps: String,
    pub out: PathBuf,
    pub quality: Quality,
    /// Training, wall-clock minutes (default: the quality's).
    pub minutes: Option<f64>,
    /// Training by passes over the data instead of minutes: reproducible bit for bit, as a
    /// time budget is not (tests).
    pub epochs: Option<usize>,
    /// Where the dataset's cameras go (default: the scene's camera volume).
    pub camera: CameraChoice,
    /// Maps of a folder held out for the check (default: a fifth).
    pub test_maps: Option<usize>,
    pub seed: u64,
    pub engine: Engine,
    pub progress: bool,
    /// Trains in a window instead of headless (`nprt bake --view`), for minutes only.
    pub view: Option<TrainingWindow>,
}

/// A bake's training as a window runs it (`nprt bake --view`, which passes `nprt view
/// --train`'s): the window returns when it is closed, the run saved.
pub struct WindowedRun<'a> {
    pub data: &'a Path,
    pub model: &'a Path,
    pub config: &'a ModelConfig,
    pub opts: &'a TrainOptions,
    pub engine: Engine,
}

/// What trains a bake's run in a window; this crate opens none itself (the window is
/// nprt-render's, behind its `view` feature).
#[derive(Clone)]
pub struct TrainingWindow(pub Arc<TrainsInWindow>);

/// Trains a bake's run in a window, returning when the run ends or the window closes.
pub type TrainsInWindow = dyn Fn(&WindowedRun) -> Result<()> + Send + Sync;

impl std::fmt::Debug for TrainingWindow {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("TrainingWindow")
    }
}

/// What a bake made, and how its model did against path tracing.
pub struct Baked {
    pub model: PathBuf,
    /// The model's frame of a held-out view beside its path-traced reference.
    pub comparison: PathBuf,
    /// The first such frame, from the model after its first minutes of training.
    pub preview: PathBuf,
    /// The check's report.html.
    pub report: PathBuf,
    /// The model as run time runs it, in words.
    pub description: String,
    /// The model's row in the check as run time makes its frames (its traced light denoised
    /// where that measured better and OIDN is installed), and path tracing of its cost
    /// (denoised where OIDN is installed).
    pub model_row: MethodResult,
    pub path_tracing: Option<MethodResult>,
    /// Held-out views checked.
    pub views: usize,
    /// Its traced light raw and denoised in the check, and which measured better (None
    /// without OIDN).
    pub check: Option<DenoiseCheck>,
    /// The maps of those views (at most three), as the dataset records them.
    pub held_out_maps: Vec<String>,
    /// Wall-clock seconds of this call.
    pub seconds: f64,
}

/// The stages, as the progress bar names them.
const STAGES: [&str; 3] = ["dataset", "training", "check"];

impl Bake {
    /// A bake of `scene` under `envmaps` into `out` at `quality`, on `engine`, with every
    /// other choice its default.
    pub fn new(scene: &str, envmaps: &str, out: &Path, quality: Quality, engine: Engine) -> Self {
        Bake {
            scene: scene.into(),
            envmaps: envmaps.into(),
            out: out.into(),
            quality,
            minutes: None,
            epochs: None,
            camera: CameraChoice::default(),
            test_maps: None,
            seed: 0,
            engine,
            progress: true,
            view: None,
        }
    }

    pub fn model_dir(&self) -> PathBuf {
        self.out.join("model")
    }

    fn data_dir(&self) -> PathBuf {
        self.out.join("dataset")
    }

    /// Refuses, before any work, a training length outside [`nprt_net::check_minutes`]'s range and paths
    /// that are not UTF-8 (the bake prints them as commands to run), naming the flag.
    fn check_settings(&self) -> Result<()> {
        if let Some(m) = self.minutes {
            nprt_net::check_minutes(m, "--minutes").map_err(anyhow::Error::msg)?;
        }
        if self.epochs == Some(0) {
            bail!("--epochs must be at least 1");
        }
        if self.view.is_some() && self.epochs.is_some() {
            bail!("--view trains for minutes: drop --epochs");
        }
        if self.out.to_str().is_none() {
            bail!(
                "--out '{}' is not valid UTF-8: nprt bake prints it in the commands to use the model; use a path of UTF-8 characters",
                self.out.display()
            );
        }
        Ok(())
    }

    /// Runs every stage not already done, in order.
    pub fn run(&self) -> Result<Baked> {
        let start = Instant::now();
        self.check_settings()?;
        // The scene and its camera volume, then the maps, first: a scene without a volume, maps
        // that cannot be listed or held out are refused before any folder is made.
        let scene = nprt_scene::load_scene(&self.scene, &nprt_data::dataset::relit())?;
        let volume = self.camera.resolve(&scene, &self.scene)?;
        let sizes = self.quality.sizes_for(scene.bounds(), &volume);
        let generate_opts = self.generate_options(&sizes);
        generate_opts.lighting()?;
        if self.out.exists() && !self.out.is_dir() {
            bail!("--out '{}' is not a folder", self.out.display());
        }
        std::fs::create_dir_all(&self.out)
            .with_context(|| format!("cannot create '{}'", self.out.display()))?;
        let _lock = nprt_io::lock_folder(&self.out, "bake folder", "--out")?;
        let claim = self.claim(&sizes)?;
        let estimates = self.estimates(&scene, &volume, &sizes, &generate_opts);
        let stages: Vec<(&str, f64)> = STAGES.into_iter().zip(estimates).collect();
        let bar = nprt_io::StagedBar::new(self.progress, &stages);
        let say = |line: &str| {
            if self.progress {
                bar.println(line)
            }
        };
        say(&self.plan(&sizes));
        let data = self.data_dir();
        bar.begin(0);
        let s = generate(&generate_opts, |p| {
            for w in &p.warnings {
                say(&format!("warning: {w}"));
            }
        })?;
        if let Some(c) = claim {
            c.write()?;
        }
        say(&format!(
            "dataset '{}': {} views rendered in {:.0} s, {} already complete",
            data.display(),
            s.rendered,
            s.seconds,
            s.skipped
        ));
        bar.begin(1);
        let config = RECIPE.config();
        let preview = self.out.join("preview.png");
        self.train(&data, &config, &sizes, &preview, &say)?;
        bar.begin(2);
        let (evaluation, check) = self.check(&data, &config, &sizes)?;
        bar.begin(STAGES.len());
        drop(bar);
        let mut baked = self.baked(&evaluation, &config, check)?;
        baked.seconds = start.elapsed().as_secs_f64();
        Ok(baked)
    }

    /// After the window closed: the bake goes on to its check only with the run done; the
    /// preview is the trained model's frame.
    fn windowed_run_ended(&self, data: &Path, preview: &Path, say: &dyn Fn(&str)) -> Result<()> {
        let model = self.model_dir();
        let file = nprt_net::read_model_file(&model)
            .context("the window closed before the run saved a model; run the bake again")?;
        let done = file.trained_seconds().unwrap_or(0.0);
        let minutes = file.run_minutes().unwrap_or(0.0);
        if done < minutes * 60.0 {
            bail!(
                "the window closed after {:.2} of the run's {minutes} minutes of training; the \
                 model is saved: the same `nprt bake` (with --minutes {minutes}, --view or not) \
                 continues it, then checks it",
                done / 60.0
            );
        }
        if !preview.is_file() {
            write_comparison(&model, data, self.engine, preview)?;
            say(&format!(
                "preview: '{}' (the trained model beside the path-traced reference)",
                preview.display()
            ));
        }
        Ok(())
    }

    /// What the bake will do, in one line.
    fn plan(&self, sizes: &Sizes) -> String {
        let training = match self.epochs {
            Some(e) => format!("{e} epochs"),
            None => format!("{} minutes", self.minutes.unwrap_or(sizes.minutes)),
        };
        format!(
            "baking {} under {} maps at {} quality: {} training views of {}², {} held-out views; \
             training {training}",
            self.scene,
            self.envmaps,
            self.quality,
            sizes.train_views,
            sizes.train_res,
            sizes.test_views,
        )
    }

    /// The check: the model against every baseline on the held-out views (cached by its
    /// inputs), whether its traced light measured better denoised (kept beside it), and its
    /// frame beside a reference (comparison.png).
    fn check(
        &self,
        data: &Path,
        config: &ModelConfig,
        sizes: &Sizes,
    ) -> Result<(Evaluation, Option<DenoiseCheck>)> {
        let model = self.model_dir();
        let opts = EvalOptions {
            data: data.to_path_buf(),
            models: vec![model.clone()],
            sh_spp: sizes.sh_spp,
            timing_res: sizes.test_res,
            shown_views: 1,
            temporal_frames: 0,
            progress: self.progress,
            ..EvalOptions::default()
        };
        let report = self.out.join("report");
        let (evaluation, _) = stages::evaluation(self.engine, &opts, &report)?;
        let check = denoise_check(&model, &evaluation, config)?;
        if let Some(c) = &check {
            c.write(&model)?;
        }
        let comparison = self.out.join("comparison.png");
        write_comparison(&model, data, self.engine, &comparison)?;
        Ok((evaluation, check))
    }

    /// What the bake made, its model as run time makes its frames.
    fn baked(
        &self,
        evaluation: &Evaluation,
        config: &ModelConfig,
        check: Option<DenoiseCheck>,
    ) -> Result<Baked> {
        let model = self.model_dir();
        let r = nprt_render::Relighter::load(&model, self.engine)?;
        let denoiser = Denoise::default().denoiser(&r, &model)?;
        let description = r.describe(&nprt_render::DirectSampling {
            spp: nprt_render::DEFAULT_DIRECT_SPP,
            seed: 0,
            denoiser,
        });
        let (model_row, path_tracing) = rows(evaluation, config, denoiser.is_some())?;
        let manifest = nprt_data::dataset::load_manifest(&self.data_dir())?;
        let held_out_maps = (manifest.settings.test_maps.iter().take(3))
            .map(|&k| manifest.settings.envmaps[k].spec.clone())
            .collect();
        Ok(Baked {
            held_out_maps,
            check,
            model,
            comparison: self.out.join("comparison.png"),
            preview: self.out.join("preview.png"),
            report: self.out.join("report").join("report.html"),
            description,
            model_row,
            path_tracing,
            views: evaluation.test_views,
            seconds: 0.0,
        })
    }

    /// The dataset: the quality's sizes, the recipe's transfer vectors where the tracer records
    /// them.
    pub fn generate_options(&self, sizes: &Sizes) -> GenerateOptions {
        let device = self.engine.tracer();
        GenerateOptions {
            scene: self.scene.clone(),
            envmaps: self.envmaps.clone(),
            out: self.data_dir(),
            views: ViewSpec {
                train_views: sizes.train_views,
                test_views: sizes.test_views,
                train_resolution: [sizes.train_res; 2],
                test_resolution: [sizes.test_res; 2],
                spp: sizes.spp,
                test_spp: sizes.test_spp,
                seed: self.seed,
                ..ViewSpec::default()
            },
            transfer: RECIPE.dataset_transfer_on(device),
            test_maps: self.test_maps,
            camera: self.camera.clone(),
            device,
            progress: self.progress,
            ..GenerateOptions::default()
        }
    }

    /// Trains (or resumes) the recipe; writes `preview` from the model after the quality's
    /// preview minutes (or at the end of a shorter run) unless a run before wrote it.
    fn train(
        &self,
        data: &Path,
        config: &ModelConfig,
        sizes: &Sizes,
        preview: &Path,
        say: &dyn Fn(&str),
    ) -> Result<()> {
        let manifest = nprt_data::dataset::load_manifest(data)?;
        let run = match self.epochs {
            Some(e) => RunLength::epochs(e),
            None => RunLength::minutes(self.minutes.unwrap_or(sizes.minutes)),
        };
        let defaults = TrainOptions::default();
        let mut opts = TrainOptions {
            calibration: RECIPE.calibration,
            targets: RECIPE.targets(config, manifest.settings.transfer),
            schedule: nprt_net::Schedule {
                seed: self.seed,
                progress: self.progress,
                ..defaults.schedule.clone()
            },
            ..defaults
        }
        .with_run(config.design, run, None);
        let model = self.model_dir();
        if let Some(window) = &self.view {
            let run = WindowedRun {
                data,
                model: &model,
                config,
                opts: &opts,
                engine: self.engine,
            };
            (window.0)(&run)?;
            return self.windowed_run_ended(data, preview, say);
        }
        let set = TrainingSet::load(data, config, self.progress, |why| say(why))?;
        if nprt_net::training::checkpoint::exists(&model) {
            say(&format!(
                "training resumes where a run before stopped ('{}')",
                model.display()
            ));
        }
        let first = !preview.is_file();
        if first {
            opts.schedule.pause_after = Some(sizes.preview_minutes);
        }
        // A stop asked for from Python (Ctrl-C) ends the training at an epoch's end, saved.
        let go_on = |_: &_| !nprt_io::interrupt::requested();
        let train = |opts: &TrainOptions| {
            let watch = nprt_net::Watch::epochs(&go_on);
            nprt_net::train(&set, config, opts, &model, self.engine, watch)
        };
        let (s, _) = train(&opts)?;
        nprt_io::interrupt::check()?;
        if first {
            write_comparison(&model, data, self.engine, preview)?;
            say(&format!(
                "preview: '{}' (the model after {:.1} minutes of training, beside the path-traced reference)",
                preview.display(),
                s.seconds / 60.0
            ));
        }
        if s.paused {
            opts.schedule.pause_after = None;
            train(&opts)?;
        }
        nprt_io::interrupt::check()
    }

    /// Seconds each stage is expected to take: the dataset's paths at the rate of a small
    /// probe render of this scene, the training its budget, the check its paths likewise.
    fn estimates(
        &self,
        scene: &nprt_scene::Scene,
        volume: &nprt_scene::CameraVolume,
        sizes: &Sizes,
        opts: &GenerateOptions,
    ) -> [f64; 3] {
        let ts = TraceScene::new(scene);
        let side = sizes.train_res.min(64);
        let camera = CameraPath::through_volume(volume).camera(0.5, side, side);
        let (probe, spp) = (Instant::now(), 4);
        let map = nprt_scene::open_envmap("builtin:sky").ok();
        if let Some(map) = &map {
            let settings = RenderSettings {
                spp,
                max_depth: scene.max_depth,
                rr_depth: scene.rr_depth,
                seed: 0,
                filter: PixelFilter::Centre,
                progress: false,
            };
            render(&ts, &camera, map, &settings);
        }
        let rate = (side * side * spp) as f64 / probe.elapsed().as_secs_f64().max(1e-6);
        let pixels = |views: u64, res: u32| views as f64 * f64::from(res * res);
        // Transfer vectors cost about three quarters of the training views' paths again.
        let transfer = if opts.transfer.is_some() { 1.75 } else { 1.0 };
        let dataset = pixels(sizes.train_views, sizes.train_res) * f64::from(sizes.spp) * transfer
            + pixels(sizes.test_views, sizes.test_res) * f64::from(sizes.test_spp);
        // The check: path tracing at 5 spp and at equal time (about 8), both denoised, the
        // model's traced light, and SH PRT's transport.
        let check = pixels(sizes.test_views, sizes.test_res) * f64::from(30 + sizes.sh_spp);
        let training = match self.epochs {
            Some(e) => e as f64 * pixels(sizes.train_views, sizes.train_res) / 1e5,
            None => self.minutes.unwrap_or(sizes.minutes) * 60.0,
        };
        [dataset / rate, training, check / rate]
    }

    /// What the folder is for: another bake into it is refused rather than mixed in.
    fn claim(&self, sizes: &Sizes) -> Result<Option<Claim>> {
        let what = json!({
            "scene": self.scene,
            "envmaps": self.envmaps,
            "quality": self.quality.name(),
            "train_views": sizes.train_views,
            "minutes": self.minutes,
            "epochs": self.epochs,
            "seed": self.seed,
            "test_maps": self.test_maps,
            "camera_volume": self.camera.file,
            "recipe": RECIPE.config().label(),
        });
        Claim::check(&self.out, "bake.json", "bake", what)
    }
}

/// The model's row in the check as run time makes its frames (`denoised` or raw), and the
/// path tracing of its cost it is held to, denoised where OIDN made that row: the stronger of
/// the two.
fn rows(
    e: &Evaluation,
    config: &ModelConfig,
    denoised: bool,
) -> Result<(MethodResult, Option<MethodResult>)> {
    let raw = row_name(config);
    let name = match denoised {
        true => format!("{raw} + OIDN"),
        false => raw.clone(),
    };
    let row = (e.method(&name).or_else(|| e.method(&raw)))
        .with_context(|| format!("the check has no row '{name}'"))?
        .clone();
    let peer = (e.method(&raw).and_then(|m| m.equal_time.clone()))
        .map(|pt| pt.trim_end_matches(" + OIDN").to_string())
        .and_then(|pt| e.method(&format!("{pt} + OIDN")).or_else(|| e.method(&pt)))
        .cloned();
    Ok((row, peer))
}

/// Whether the model's traced light measured better denoised or raw in the check (None where
/// OIDN made no denoised row): kept beside the model for `Denoise::Auto`.
fn denoise_check(
    model: &Path,
    e: &Evaluation,
    config: &ModelConfig,
) -> Result<Option<DenoiseCheck>> {
    let raw = row_name(config);
    let (Some(r), Some(d)) = (e.method(&raw), e.method(&format!("{raw} + OIDN"))) else {
        return Ok(None);
    };
    let errors = |m: &MethodResult| [m.mean.l1, m.mean.rmse, m.mean.dssim];
    DenoiseCheck::measured(model, e.test_views, errors(r), errors(d)).map(Some)
}
