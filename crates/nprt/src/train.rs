//! `nprt train`: flags for training one design; the work is `nprt_net::train`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use nprt_net::network::encoder::check_input_width;
use nprt_net::training::training_set::{TrainingSet, ViewSamples};
use nprt_net::{
    Activation, Asked, BasisChoice, Calibration, Design, DirectLight, Engine, Gather, Loss,
    MapNorm, ModelConfig, PositionEncoding, Precision, Targets, TrainOptions,
    DEFAULT_ENCODER_WIDTH, DEFAULT_MAP_NORM,
};

use crate::flags::{design_names, parse_snapshots, DeviceArg, RunArgs, Snapshots};

/// The defaults every flag shows, from the one place that states them.
fn d() -> TrainOptions {
    TrainOptions::default()
}

#[derive(clap::Args)]
pub struct TrainArgs {
    /// Dataset folder made by `nprt generate` (holding manifest.json). The first training packs
    /// it (one memory-mapped file beside manifest.json, made again when a view changes; see
    /// `nprt dataset pack`), so the folder must be writable then.
    #[arg(long)]
    data: PathBuf,
    /// Transport design (docs/model.md; the paper's four are its Table 1), trained with its
    /// own defaults (the paper's, for the paper's designs). Without it: the recommended recipe,
    /// nprt's measured best (the linear design on sh:2, its direct light traced, trained on
    /// the dataset's transfer vectors where it has them, its level calibrated; docs/model.md),
    /// whose choices the flags below still change one by one.
    #[arg(long, value_parser = design_names())]
    arch: Option<Design>,
    /// siren or relu for the layers that read the pixel inputs (default: the paper's choice).
    #[arg(long)]
    activation: Option<Activation>,
    /// Model folder to write; re-running with the same settings resumes the run in it, and a
    /// larger --epochs or --minutes continues a finished one (with --schedule paper).
    #[arg(long)]
    out: PathBuf,
    /// The run's length (--epochs: passes over all foreground pixels of the training views,
    /// the paper: 500; on 2 CPU cores one epoch of the default 400-view 128² dataset takes
    /// about 4 minutes with dsep) and learning-rate schedule.
    #[command(flatten)]
    run: RunArgs,
    /// Samples per batch.
    #[arg(long, default_value_t = d().batch_size)]
    batch_size: usize,
    /// Adam's (peak) learning rate [default with --schedule cosine: 5e-4 for prt, albedo and
    /// dsep, 3e-4 for baseline, measured on demo-sized data (docs/model.md); with --schedule
    /// paper, the paper's 1e-4].
    #[arg(long, value_parser = crate::flags::finite_f64)]
    lr: Option<f64>,
    /// Seed of the initial weights and of the batch order.
    #[arg(long, default_value_t = d().schedule.seed)]
    seed: u64,
    /// Keep the model at these points of the run, each in OUT/snapshots/POINT/ (weights and
    /// config, no optimiser state): minutes of training time as Nm, epochs as N,
    /// comma-separated (e.g. 1m,2m,4m,8m,16m). A resumed run keeps those it has; a point
    /// passed before without being kept is not kept later. `nprt paper --snapshots` measures
    /// them.
    #[arg(long, value_name = "LIST", value_parser = parse_snapshots)]
    snapshots: Option<Snapshots>,
    /// Views whose pixels are mixed in each batch, each lit by its own rotated map.
    #[arg(long, default_value_t = d().views_per_batch)]
    views_per_batch: usize,
    /// Training loss: log-l1 (the paper's L1 on log(1 + x): minimised by the median of what the
    /// network cannot tell apart, target noise or detail not yet learnt, which is darker than
    /// the mean) or rel-l2 ((p − r)² / (p² + 0.01) with p held constant in the denominator,
    /// minimised by the mean: right in level, worse in detail at short budgets; see
    /// docs/model.md). The validation loss is log-L1 either way.
    #[arg(long, default_value_t = d().loss)]
    loss: Loss,
    /// What the network learns: radiance (each pixel under its view's lighting, the paper's)
    /// or transfer (the linear design on an SH basis, --arch linear --basis sh:L, learns each
    /// pixel's transfer vector as `nprt generate --transfer sh:L` recorded it, by the mean
    /// squared error of its coefficients: one target for every lighting at once, whose
    /// minimiser on noisy vectors is their mean; --loss then does not apply). On either engine;
    /// docs/model.md. [default: radiance with --arch; without it, the recipe's: transfer where
    /// the dataset holds vectors of the model's basis, else radiance]
    #[arg(long)]
    targets: Option<Targets>,
    /// none (the network's output as it is, the paper) or level (each channel of the saved
    /// model's radiance multiplied by the training targets' mean over its own, measured on
    /// training pixels whenever the model is saved, and again when a finished run is asked
    /// with another choice: log-L1 settles on a median, darker than the mean. It gets the level
    /// right but costs L1 where the darkness is light the network cannot place, as in the demo;
    /// docs/model.md). [default: none with --arch; level for the recipe]
    #[arg(long)]
    calibrate: Option<Calibration>,
    /// Test-view pixels (held-out lighting) used for the validation loss after each epoch.
    #[arg(long, default_value_t = d().val_samples)]
    val_samples: usize,
    /// Width W of the encoder's W × W/2 input map (a multiple of 64).
    #[arg(long, default_value_t = DEFAULT_ENCODER_WIDTH)]
    encoder_width: usize,
    /// What the map is divided by before the encoder sees it, the prediction multiplied by the
    /// same: channel (each channel's mean, so a held-out map's tint carries over exactly) or
    /// mean (the paper's one mean over channels, which leaves colour to the encoder).
    #[arg(long, default_value_t = DEFAULT_MAP_NORM)]
    map_norm: MapNorm,
    /// learned (the paper: the network predicts all the radiance) or traced (the network
    /// learns the indirect light only, the reference minus its direct part, and `nprt render`
    /// and `nprt eval` trace the direct light at run time with --direct-spp samples per pixel,
    /// its cost counted in the model's time; docs/model.md). [default: learned with --arch;
    /// traced for the recipe]
    #[arg(long)]
    direct: Option<DirectLight>,
    /// How the transport network sees the position: none (the paper: x, y, z only) or hash-grid
    /// (a multiresolution hash grid on the scene's box, 8 levels from 4 to 64 cells a side,
    /// 2^13 × 2 learned values each, 0.5 MB per track, whose interpolated values join the
    /// inputs; docs/model.md). The design's layers are otherwise unchanged.
    #[arg(long, default_value_t = PositionEncoding::default())]
    encoding: PositionEncoding,
    /// The linear design's light basis (--arch linear only): sh:L, real spherical harmonics of
    /// bands 0 to L ((L+1)² functions per colour channel, fixed), or learned:K, K functions
    /// trained with the network, started from the harmonics that fit (docs/model.md). Default
    /// sh:4 (SH PRT 25's lighting) with --arch linear; sh:2 for the recipe.
    #[arg(long)]
    basis: Option<BasisChoice>,
    /// Minutes between checkpoints within an epoch. An epoch's end writes one once these
    /// minutes or 10 seconds have passed since the last (0: at every epoch's end); the run's
    /// end always does.
    #[arg(long, value_parser = crate::flags::finite_f64, default_value_t = d().schedule.checkpoint_secs / 60.0)]
    checkpoint_minutes: f64,
    /// Stop this call after these minutes of training, saved, wherever the run stands (its
    /// length, learning-rate schedule and --snapshots unchanged); the same command continues
    /// it. How a long run is advanced a few minutes at a time (bench/kitchen-visit.sh).
    #[arg(long, value_name = "MINUTES", value_parser = crate::flags::finite_f64)]
    pause_after: Option<f64>,
    /// On the GPU kernels (--device gpu or wgpu), where batches are gathered: device (the
    /// dataset's records, 40 bytes a pixel, and maps are uploaded once, and each step gathers
    /// its batch there from the picked samples) or host (each batch is gathered here and uploaded, for a dataset the
    /// GPU has no room for). The batches are the same either way.
    #[arg(long, default_value_t = d().gather)]
    gather: Gather,
    /// On the GPU kernels (--device gpu or wgpu), the transport networks' products: f32, or f16
    /// (mixed precision: weights, activations and gradients between layers held as f16 and
    /// summed in f32, on
    /// tensor cores where the GPU has cooperative matrices; master weights, Adam, the light
    /// encoder and the hash grids stay f32; the loss's gradient is scaled so that f16 keeps it;
    /// docs/model.md). Elsewhere f32 only.
    #[arg(long, default_value_t = d().precision)]
    precision: Precision,
    #[command(flatten)]
    device: DeviceArg,
}

/// One training run as the library takes it.
pub struct TrainJob {
    pub data: PathBuf,
    pub config: ModelConfig,
    pub opts: TrainOptions,
    pub out: PathBuf,
    /// What was asked: the targets follow from it and the dataset (`opts.targets` is set from
    /// them once the dataset is loaded).
    pub asked: Asked,
}

impl TryFrom<TrainArgs> for TrainJob {
    type Error = anyhow::Error;
    fn try_from(a: TrainArgs) -> Result<Self> {
        check_input_width(a.encoder_width)?;
        let asked = Asked {
            design: a.arch,
            activation: a.activation,
            direct: a.direct,
            basis: a.basis,
            calibration: a.calibrate,
            targets: a.targets,
        };
        let config = ModelConfig {
            encoder_width: a.encoder_width,
            map_norm: a.map_norm,
            encoding: a.encoding,
            ..asked.config()?
        };
        let opts = TrainOptions {
            schedule: nprt_net::Schedule {
                seed: a.seed,
                checkpoint_secs: a.checkpoint_minutes * 60.0,
                snapshots: a.snapshots.map(|s| s.0).unwrap_or_default(),
                pause_after: a.pause_after,
                ..d().schedule
            },
            batch_size: a.batch_size,
            views_per_batch: a.views_per_batch,
            val_samples: a.val_samples,
            loss: a.loss,
            calibration: asked.calibration(),
            gather: a.gather,
            precision: a.precision,
            ..d()
        }
        .with_run(config.design, a.run.into(), a.lr);
        opts.check().context("bad training options")?;
        Ok(TrainJob {
            data: a.data,
            config,
            opts,
            out: a.out,
            asked,
        })
    }
}

pub fn command(a: TrainArgs) -> Result<()> {
    let engine = a.device.engine()?;
    run(&TrainJob::try_from(a)?, engine)
}

/// Loads the dataset, trains and prints what the run did.
pub fn run(job: &TrainJob, engine: Engine) -> Result<()> {
    let t0 = std::time::Instant::now();
    let set = TrainingSet::load(&job.data, &job.config, job.opts.schedule.progress, |why| {
        eprintln!("{why}")
    })?;
    print_dataset(&job.data, &set, t0.elapsed().as_secs_f64());
    let opts = TrainOptions {
        targets: (job.asked).targets(&job.config, set.manifest.settings.transfer),
        ..job.opts.clone()
    };
    println!(
        "{}",
        training_line(&job.config, &opts, job.asked.recipe().is_some())
    );
    let (s, file) = nprt_net::train(
        &set,
        &job.config,
        &opts,
        &job.out,
        engine,
        nprt_net::Watch::default(),
    )?;
    if let Some(e) = s.resumed_from_epoch {
        println!("resumed from epoch {e:.2}");
    }
    let config = &job.config;
    println!(
        "trained {} ({}) for {:.2} epochs: {} steps, {:.2} M samples in {:.1} s ({:.0} K samples/s); training loss {:.5}, validation loss {:.5}",
        config.label(),
        config.activation,
        s.epochs,
        s.steps,
        s.samples as f64 / 1e6,
        s.seconds,
        s.samples as f64 / s.seconds.max(1e-9) / 1e3,
        s.final_train,
        s.final_val
    );
    println!("time: {} (steps on {})", s.split.describe(), s.steps_on);
    if s.paused {
        println!(
            "paused (--pause-after {}) at {:.2} minutes of training; the same command continues",
            job.opts.schedule.pause_after.unwrap_or(0.0),
            s.seconds / 60.0
        );
    }
    if let Some([r, g, b]) = file.level_gain {
        println!(
            "level gain (training targets' mean over the network's, per channel): R {r:.3} G {g:.3} B {b:.3}"
        );
    }
    println!(
        "model in '{}' (loss curves: loss.csv, loss.png)",
        job.out.display()
    );
    Ok(())
}

/// What a run trains, in one line: "training the recommended recipe: linear design on sh:2,
/// direct light traced, on transfer vectors, level calibrated".
fn training_line(config: &ModelConfig, opts: &TrainOptions, recipe: bool) -> String {
    let what = match recipe {
        true => "the recommended recipe: ".to_string(),
        false => String::new(),
    };
    let calibrated = match opts.calibration {
        Calibration::Level => ", level calibrated",
        Calibration::None => "",
    };
    format!(
        "training {what}{}, on {}{calibrated}",
        config.describe(),
        match opts.targets {
            Targets::Radiance => "radiance",
            Targets::Transfer => "transfer vectors",
        }
    )
}

fn print_dataset(dir: &Path, set: &TrainingSet, seconds: f64) {
    let count = |v: &[ViewSamples]| v.iter().map(|s| s.len()).sum::<usize>();
    println!(
        "dataset '{}': {} training views ({} foreground pixels), {} test views ({} pixels), {:.2} GB packed (mapped; only the views in use are resident), {:.2} GB of maps in memory, loaded in {seconds:.1} s",
        dir.display(),
        set.train.len(),
        count(&set.train),
        set.test.len(),
        count(&set.test),
        set.pack.bytes() as f64 / 1e9,
        set.bytes() as f64 / 1e9,
    );
}
