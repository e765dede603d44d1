//! Training beside the viewer's frames (`nprt view --train`): the run goes on a thread of its
//! own through nprt-net's one training loop, watched through a [`LiveRun`]; the viewer takes
//! each model it publishes. A run whose time is spent and then lengthened resumes from its
//! checkpoint, as `nprt train` would.

use std::path::PathBuf;
use std::sync::Arc;
use std::thread::JoinHandle;

use anyhow::{anyhow, bail, Context, Result};
use nprt_data::dataset::{load_manifest, Manifest};
use nprt_net::training::live::{LiveRun, LiveStatus};
use nprt_net::training::training_loop::check_model_folder;
use nprt_net::training::training_set::TrainingSet;
use nprt_net::{
    read_model_file, Asked, Engine, ModelConfig, ModelFile, NprtNet, RunLength, TrainOptions,
    TrainSummary, Watch,
};

/// Minutes a run trains when neither `--minutes` nor the model folder says.
pub const DEFAULT_MINUTES: f64 = 10.0;

/// A training run to watch.
pub struct TrainingJob {
    /// The dataset folder.
    pub data: PathBuf,
    /// The model folder (a run there continues).
    pub out: PathBuf,
    pub config: ModelConfig,
    /// The run's options; its length is `minutes`'.
    pub opts: TrainOptions,
    /// What was asked: the targets follow from it and the dataset.
    pub asked: Asked,
    /// The run's length: given, else the model folder's own (so that a run continues under
    /// the key it was saved with), else [`DEFAULT_MINUTES`].
    pub minutes: Option<f64>,
    /// Where the steps run.
    pub engine: Engine,
}

/// A run going on beside the window.
pub struct Training {
    job: TrainingJob,
    pub manifest: Manifest,
    live: Arc<LiveRun>,
    thread: Option<JoinHandle<Result<TrainSummary>>>,
    /// How the last thread ended, once it has.
    outcome: Option<Result<TrainSummary, String>>,
    /// Models of this thread's run taken so far.
    seen: u64,
    /// Whether the viewer asked the run to pause.
    paused: bool,
}

impl Training {
    /// Reads the dataset's manifest (the scene, its camera volume and maps) and starts the
    /// run; the training set loads on the run's thread, so that the window opens at once.
    pub fn start(mut job: TrainingJob) -> Result<Self> {
        let manifest = load_manifest(&job.data)
            .with_context(|| format!("--train '{}'", job.data.display()))?;
        // Refused before the window opens, not on the run's thread.
        check_model_folder(&job.out)?;
        if job.out.is_file() {
            bail!(
                "--out '{}' is a file; a model goes into a folder",
                job.out.display()
            );
        }
        let minutes = job
            .minutes
            .or_else(|| recorded_minutes(&job.out))
            .unwrap_or(DEFAULT_MINUTES);
        nprt_net::check_minutes(minutes, "--minutes").map_err(anyhow::Error::msg)?;
        job.opts.schedule = RunLength::minutes(minutes).apply(job.opts.schedule.clone());
        job.opts.schedule.progress = false;
        job.opts.check()?;
        let mut training = Training {
            job,
            manifest,
            live: Arc::new(LiveRun::default()),
            thread: None,
            outcome: None,
            seen: 0,
            paused: false,
        };
        training.spawn();
        Ok(training)
    }

    fn spawn(&mut self) {
        let live = Arc::new(LiveRun::default());
        self.live = live.clone();
        self.seen = 0;
        self.outcome = None;
        self.paused = false;
        let job = &self.job;
        let (data, out, config, opts, asked, engine) = (
            job.data.clone(),
            job.out.clone(),
            job.config.clone(),
            job.opts.clone(),
            job.asked,
            job.engine,
        );
        self.thread = Some(std::thread::spawn(move || {
            let set = TrainingSet::load(&data, &config, false, |why| eprintln!("{why}"))?;
            let opts = TrainOptions {
                targets: asked.targets(&config, set.manifest.settings.transfer),
                ..opts
            };
            let watch = Watch::live(&live);
            Ok(nprt_net::train(&set, &config, &opts, &out, engine, watch)?.0)
        }));
    }

    /// The model folder.
    pub fn out(&self) -> &std::path::Path {
        &self.job.out
    }

    /// The run's time budget in minutes.
    pub fn minutes(&self) -> f64 {
        self.job.opts.schedule.minutes.unwrap_or(DEFAULT_MINUTES)
    }

    /// Where the run stands.
    pub fn status(&self) -> LiveStatus {
        self.live.status()
    }

    /// The model the run published last, if it is newer than the last one taken; a newer one
    /// is asked for.
    pub fn newest_model(&mut self) -> Option<(ModelFile, NprtNet)> {
        self.live.want_model();
        let (n, file, net) = self.live.model_after(self.seen)?;
        self.seen = n;
        Some((file, net))
    }

    /// How the run ended, once it has: its summary, or what stopped it.
    pub fn outcome(&mut self) -> Option<&Result<TrainSummary, String>> {
        if self.thread.as_ref().is_some_and(|t| t.is_finished()) {
            self.outcome = Some(self.join());
        }
        self.outcome.as_ref()
    }

    fn join(&mut self) -> Result<TrainSummary, String> {
        let thread = self.thread.take().expect("a run's thread");
        match thread.join() {
            Ok(done) => done.map_err(|e| format!("{e:#}")),
            Err(_) => Err("the training thread panicked".into()),
        }
    }

    /// Pauses the run, or resumes it if it was paused; returns whether it is now paused.
    pub fn toggle_pause(&mut self) -> bool {
        self.paused = !self.paused;
        self.live.pause(self.paused);
        self.paused
    }

    /// Asks the run to save at its next step (`status().saved_at` says when it has).
    pub fn save(&self) {
        self.live.save();
    }

    /// Lengthens the run by `minutes`: while it goes, at its next step; once its time is
    /// spent, by resuming it from its checkpoint for the longer budget.
    pub fn extend(&mut self, minutes: f64) -> Result<()> {
        let schedule = &mut self.job.opts.schedule;
        schedule.minutes = Some(schedule.minutes.unwrap_or(DEFAULT_MINUTES) + minutes);
        if self.thread.is_none() || self.outcome().is_some() {
            match self.outcome.take() {
                Some(Err(e)) => return Err(anyhow!("training had failed: {e}")),
                _ => self.spawn(),
            }
        } else {
            self.live.extend(minutes);
        }
        Ok(())
    }

    /// Stops the run, saved (atomically, resumable), and says how it ended.
    pub fn finish(mut self) -> Result<Option<TrainSummary>> {
        self.live.stop();
        if self.thread.is_some() {
            self.outcome = Some(self.join());
        }
        match self.outcome {
            Some(Ok(s)) => Ok(Some(s)),
            Some(Err(e)) => Err(anyhow!("training in the viewer failed: {e}")),
            None => Ok(None),
        }
    }
}

/// The length (minutes) the run in model folder `out` was saved with, if it holds one.
fn recorded_minutes(out: &std::path::Path) -> Option<f64> {
    read_model_file(out).ok()?.run_minutes()
}
