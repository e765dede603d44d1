//! `nprt model info`, `nprt train` and `nprt bench train`.

use std::path::PathBuf;
use std::process::Command as Process;

use anyhow::{bail, Context, Result};
use nprt_net::data::TrainingSet;
use nprt_net::encoder::check_input_width;
use nprt_net::{device_name, is_cpu, Backend, Device};

use crate::{DeviceArg, RunLength};
use nprt_net::{
    layer_table, measure_throughput, median, recipe_rate, Activation, Calibration, Design,
    DirectLight, Engine, Init, Loss, MapNorm, ModelConfig, PositionEncoding, Schedule,
    TrainOptions, DEFAULT_ENCODER_WIDTH, DEFAULT_MAP_NORM,
};

#[derive(clap::Args)]
pub struct ModelInfoArgs {
    /// Transport design: baseline, prt (PRT-inspired), albedo (albedo factorisation) or dsep
    /// (diffuse/specular separation).
    #[arg(long, required_unless_present = "model", conflicts_with = "model")]
    pub arch: Option<Design>,
    /// A trained model folder: load it (checking its config and weights) and describe it.
    #[arg(long)]
    model: Option<PathBuf>,
    /// Activation of the layers that read the pixel inputs (siren or relu). Default: the
    /// paper's (relu for baseline, siren for the others).
    #[arg(long)]
    pub activation: Option<Activation>,
    /// Width W of the encoder's W × W/2 input map (a multiple of 64).
    #[arg(long, default_value_t = DEFAULT_ENCODER_WIDTH)]
    pub encoder_width: usize,
    /// Position input encoding: none (the paper) or hash-grid (its tables are listed with
    /// their parameters).
    #[arg(long, default_value_t = PositionEncoding::None)]
    pub encoding: PositionEncoding,
}

#[derive(clap::Args)]
pub struct TrainArgs {
    /// Dataset folder made by `nprt generate` (holding manifest.json).
    #[arg(long)]
    pub data: PathBuf,
    /// Transport design: baseline, prt, albedo or dsep.
    #[arg(long)]
    pub arch: Design,
    /// siren or relu for the layers that read the pixel inputs (default: the paper's choice).
    #[arg(long)]
    pub activation: Option<Activation>,
    /// Model folder to write; re-running with the same settings resumes the run in it, and a
    /// larger --epochs or --minutes continues a finished one (with --schedule paper).
    #[arg(long)]
    pub out: PathBuf,
    /// The run's length (--epochs: passes over all foreground pixels of the training views,
    /// the paper: 500; on 2 CPU cores one epoch of the default 400-view 128² dataset takes
    /// about 4 minutes with dsep) and learning-rate schedule.
    #[command(flatten)]
    pub run: RunLength,
    /// Samples per batch.
    #[arg(long, default_value_t = TrainOptions::default().batch_size)]
    pub batch_size: usize,
    /// Adam's (peak) learning rate [default with --schedule cosine: 5e-4 for prt, albedo and
    /// dsep, 3e-4 for baseline, measured on demo-sized data (docs/model.md); with --schedule
    /// paper, the paper's 1e-4].
    #[arg(long)]
    pub lr: Option<f64>,
    /// Seed of the initial weights and of the batch order.
    #[arg(long, default_value_t = TrainOptions::default().schedule.seed)]
    pub seed: u64,
    /// Views whose pixels are mixed in each batch, each lit by its own rotated map.
    #[arg(long, default_value_t = TrainOptions::default().views_per_batch)]
    pub views_per_batch: usize,
    /// Training loss: log-l1 (the paper's L1 on log(1 + x): minimised by the median of what the
    /// network cannot tell apart, target noise or detail not yet learnt, which is darker than
    /// the mean) or rel-l2 ((p − r)² / (p² + 0.01) with p held constant in the denominator,
    /// minimised by the mean: right in level, worse in detail at short budgets; see
    /// docs/model.md). The validation loss is log-L1 either way.
    #[arg(long, default_value = "log-l1")]
    pub loss: Loss,
    /// none (the network's output as it is, the paper) or level (each channel of the saved
    /// model's radiance multiplied by the training targets' mean over its own, measured on
    /// training pixels whenever the model is saved, and again when a finished run is asked
    /// with another choice: log-L1 settles on a median, darker than the mean. It gets the level
    /// right but costs L1 where the darkness is light the network cannot place, as in the demo;
    /// docs/model.md).
    #[arg(long, default_value_t = TrainOptions::default().calibration)]
    pub calibrate: Calibration,
    /// Test-view pixels (held-out lighting) used for the validation loss after each epoch.
    #[arg(long, default_value_t = TrainOptions::default().val_samples)]
    pub val_samples: usize,
    /// Width W of the encoder's W × W/2 input map (a multiple of 64).
    #[arg(long, default_value_t = DEFAULT_ENCODER_WIDTH)]
    pub encoder_width: usize,
    /// What the map is divided by before the encoder sees it, the prediction multiplied by the
    /// same: channel (each channel's mean, so a held-out map's tint carries over exactly) or
    /// mean (the paper's one mean over channels, which leaves colour to the encoder).
    #[arg(long, default_value_t = DEFAULT_MAP_NORM)]
    pub map_norm: MapNorm,
    /// learned (the paper: the network predicts all the radiance) or traced (the network
    /// learns the indirect light only, the reference minus its direct part, and `nprt render`
    /// and `nprt eval` trace the direct light at run time with --direct-spp samples per pixel,
    /// its cost counted in the model's time; docs/model.md).
    #[arg(long, default_value_t = DirectLight::Learned)]
    pub direct: DirectLight,
    /// How the transport network sees the position: none (the paper: x, y, z only) or hash-grid
    /// (a multiresolution hash grid on the scene's box, 8 levels from 4 to 64 cells a side,
    /// 2^13 × 2 learned values each, 0.5 MB per track, whose interpolated values join the
    /// inputs; docs/model.md). The design's layers are otherwise unchanged.
    #[arg(long, default_value_t = PositionEncoding::None)]
    pub encoding: PositionEncoding,
    /// Minutes between checkpoints within an epoch (one is always written at an epoch's end).
    #[arg(long, default_value_t = TrainOptions::default().schedule.checkpoint_secs / 60.0)]
    pub checkpoint_minutes: f64,
    #[command(flatten)]
    pub device: DeviceArg,
}

#[derive(clap::Subcommand)]
pub enum BenchCommand {
    /// Training samples/s of each design (forward, backward and Adam on one batch) with the CPU
    /// engine and with burn's autodiff graph, beside bench/train_pytorch.py running the same
    /// networks, batch and loss when --python is given; the ratio is the engine's to PyTorch's.
    Train(BenchTrainArgs),
    /// Inference speed of each design's transport networks on the CPU engine at a square
    /// resolution, every pixel foreground: a frame from a new viewpoint, and a lighting change
    /// under a still camera (transfer outputs kept), with achieved GFLOP/s beside the machine's
    /// f32 peak (measured with register-resident FMA chains on as many threads).
    Infer(BenchInferArgs),
}

/// The designs a benchmark measures.
#[derive(clap::Args)]
pub struct BenchDesigns {
    /// Designs to measure, comma-separated.
    #[arg(
        long,
        default_value = "baseline,prt,albedo,dsep",
        value_delimiter = ','
    )]
    pub arch: Vec<Design>,
}

#[derive(clap::Args)]
pub struct BenchInferArgs {
    #[command(flatten)]
    designs: BenchDesigns,
    /// Width and height of the frame in pixels (the paper's Table 3: 512).
    #[arg(long, default_value_t = 512)]
    resolution: usize,
    /// Runs per measurement; the median is reported.
    #[arg(long, default_value_t = 5)]
    repeats: usize,
    #[command(flatten)]
    device: DeviceArg,
}

#[derive(clap::Args)]
pub struct BenchTrainArgs {
    #[command(flatten)]
    designs: BenchDesigns,
    /// siren or relu (default: each design's own).
    #[arg(long)]
    pub activation: Option<Activation>,
    #[arg(long, default_value_t = 16_384)]
    pub batch_size: usize,
    /// Maps (views) per batch.
    #[arg(long, default_value_t = 8)]
    views: usize,
    /// Timed steps per design.
    #[arg(long, default_value_t = 10)]
    steps: usize,
    /// Untimed steps before them (a GPU compiles and tunes its kernels in the first steps).
    #[arg(long, default_value_t = 2)]
    warmup: usize,
    /// Rounds per design, each timing the PyTorch peer and then nprt; the medians are
    /// compared, and the range of the rounds' ratios is printed beside them.
    #[arg(long, default_value_t = 3)]
    rounds: usize,
    /// Python with PyTorch for the side-by-side peer (bench/train_vs_pytorch.sh installs one);
    /// it runs on the same device (CUDA for a GPU).
    #[arg(long)]
    python: Option<PathBuf>,
    #[command(flatten)]
    device: DeviceArg,
}

fn config(
    arch: Design,
    activation: Option<Activation>,
    encoder_width: usize,
    map_norm: MapNorm,
    direct: DirectLight,
    encoding: PositionEncoding,
) -> Result<ModelConfig> {
    check_input_width(encoder_width)?;
    Ok(ModelConfig {
        encoder_width,
        map_norm,
        direct,
        encoding,
        ..ModelConfig::new(arch, activation)
    })
}

pub fn model_info(a: ModelInfoArgs) -> Result<()> {
    let (config, net) = match (&a.model, a.arch) {
        (Some(dir), _) => {
            let (file, net) = nprt_net::load_model(dir, &Device::flex())?;
            println!(
                "model '{}': trained on dataset {} (scene {})",
                dir.display(),
                &file.dataset_hash[..12.min(file.dataset_hash.len())],
                &file.scene_hash[..12.min(file.scene_hash.len())]
            );
            if let Some([r, g, b]) = file.level_gain {
                println!(
                    "output calibrated to its training level: gain R {r:.3} G {g:.3} B {b:.3}"
                );
            }
            (file.config, net)
        }
        (None, Some(arch)) => {
            let config = config(
                arch,
                a.activation,
                a.encoder_width,
                DEFAULT_MAP_NORM,
                DirectLight::Learned,
                a.encoding,
            )?;
            let net = config.build(&mut Init::new(0, &Device::flex()));
            (config, net)
        }
        (None, None) => bail!("give --arch or --model"),
    };
    let arch = config.design;
    println!(
        "design {} ({} transport layers), light encoder input {}×{}, map normalised by its {}, direct light {}, position encoding {}",
        arch.name(),
        config.activation.name(),
        config.encoder_width,
        config.encoder_width / 2,
        match config.map_norm {
            MapNorm::Mean => "mean",
            MapNorm::Channel => "mean per channel",
        },
        match config.direct {
            DirectLight::Learned => "learned",
            DirectLight::Traced => "traced at run time",
        },
        config.encoding
    );
    println!("{:<24} {:<22} {:>10}", "layer", "shape", "params");
    for row in layer_table(&net) {
        println!("{:<24} {:<22} {:>10}", row.name, row.shape, row.params);
    }
    let transport = net.transport_params();
    let grid = net.grid_params();
    let encoder = nprt_net::NprtNet::total_params(&net) - transport;
    let paper = arch.paper_params();
    let mb = |params: usize| params as f64 * 4.0 / 1e6;
    println!("encoder parameters:   {encoder:>10}");
    println!(
        "transport parameters: {:>10} (paper: {paper}, {:+.2}%)",
        transport - grid,
        ((transport - grid) as f64 / paper as f64 - 1.0) * 100.0
    );
    if grid > 0 {
        println!(
            "hash grid entries:    {grid:>10} ({:.2} MB as f32)",
            mb(grid)
        );
    }
    println!(
        "total parameters:     {:>10} ({:.2} MB as f32)",
        transport + encoder,
        mb(transport + encoder)
    );
    Ok(())
}

/// The run's schedule: the measured recipe unless flags say otherwise.
fn training_schedule(a: &TrainArgs) -> Schedule {
    let s = a.run.apply(Schedule {
        seed: a.seed,
        checkpoint_secs: a.checkpoint_minutes * 60.0,
        progress: true,
        ..TrainOptions::default().schedule
    });
    Schedule {
        learning_rate: a.lr.unwrap_or_else(|| recipe_rate(a.arch, s.lr_schedule)),
        ..s
    }
}

pub fn train(a: TrainArgs) -> Result<()> {
    let config = config(
        a.arch,
        a.activation,
        a.encoder_width,
        a.map_norm,
        a.direct,
        a.encoding,
    )?;
    let t0 = std::time::Instant::now();
    let set = TrainingSet::load(&a.data, &config)?;
    let count = |v: &[nprt_net::data::ViewSamples]| v.iter().map(|s| s.len()).sum::<usize>();
    println!(
        "dataset '{}': {} training views ({} foreground pixels), {} test views ({} pixels), {:.2} GB in memory, loaded in {:.1} s",
        a.data.display(),
        set.train.len(),
        count(&set.train),
        set.test.len(),
        count(&set.test),
        set.bytes() as f64 / 1e9,
        t0.elapsed().as_secs_f64()
    );
    let opts = TrainOptions {
        schedule: training_schedule(&a),
        batch_size: a.batch_size,
        views_per_batch: a.views_per_batch,
        val_samples: a.val_samples,
        loss: a.loss,
        calibration: a.calibrate,
    };
    opts.check().context("bad training options")?;
    let s = nprt_net::train(&set, &config, &opts, &a.out, &a.device.device()?)?;
    if let Some(e) = s.resumed_from_epoch {
        println!("resumed from epoch {e:.2}");
    }
    println!(
        "trained {} ({}) for {:.2} epochs: {} steps, {:.2} M samples in {:.1} s ({:.0} K samples/s); training loss {:.5}, validation loss {:.5}",
        config.label(),
        config.activation.name(),
        s.epochs,
        s.steps,
        s.samples as f64 / 1e6,
        s.seconds,
        s.samples as f64 / s.seconds.max(1e-9) / 1e3,
        s.final_train,
        s.final_val
    );
    println!("time: {}", s.split.describe());
    if let Some([r, g, b]) = nprt_net::model::read_model_file(&a.out)?.level_gain {
        println!(
            "level gain (training targets' mean over the network's, per channel): R {r:.3} G {g:.3} B {b:.3}"
        );
    }
    println!(
        "model in '{}' (loss curves: loss.csv, loss.png)",
        a.out.display()
    );
    Ok(())
}

pub fn bench(cmd: BenchCommand) -> Result<()> {
    match cmd {
        BenchCommand::Train(a) => bench_train(a),
        BenchCommand::Infer(a) => bench_infer(a),
    }
}

fn bench_infer(a: BenchInferArgs) -> Result<()> {
    let device = a.device.device()?;
    // A peak is measured only for the CPU; on a GPU the column is left empty.
    let peak = is_cpu(&device).then(|| nprt_net::cpu::measured_peak(rayon::current_num_threads()));
    println!(
        "inference at {r}×{r} on {}, every pixel foreground, encoder not counted{}",
        device_name(&device),
        peak.as_ref().map_or(String::new(), |p| format!(
            "; f32 peak {:.0} GFLOP/s ({} threads, {}-lane FMA chains, measured)",
            p.gflops, p.threads, p.lanes
        )),
        r = a.resolution
    );
    println!(
        "{:<10} {:>9} {:>8} {:>6} {:>11} {:>8} {:>6} {:>8}",
        "design", "frame ms", "GFLOP/s", "peak", "relight ms", "GFLOP/s", "peak", "speed-up"
    );
    for &arch in &a.designs.arch {
        let config = ModelConfig::new(arch, None);
        let s =
            nprt_net::measure_inference(&config, a.resolution * a.resolution, a.repeats, &device);
        let pct = |g: f64| {
            peak.as_ref()
                .map_or("-".into(), |p| format!("{:.0}%", 100.0 * g / p.gflops))
        };
        println!(
            "{:<10} {:>9.1} {:>8.1} {:>6} {:>11.1} {:>8.1} {:>6} {:>7.2}×",
            arch.name(),
            s.frame_ms,
            s.frame_gflops,
            pct(s.frame_gflops),
            s.relight_ms,
            s.relight_gflops,
            pct(s.relight_gflops),
            s.frame_ms / s.relight_ms
        );
    }
    Ok(())
}

fn bench_train(a: BenchTrainArgs) -> Result<()> {
    let threads = rayon::current_num_threads();
    let device = a.device.device()?;
    let cpu = is_cpu(&device);
    let rounds = a.rounds.max(1);
    println!(
        "training throughput on {}, batch {}, {} maps per batch, {} timed steps, {threads} threads, \
         median of {rounds} rounds",
        device_name(&device),
        a.batch_size,
        a.views,
        a.steps
    );
    // PyTorch's device of the same kind; it has none for wgpu.
    let torch_device = match Backend::of(&device) {
        Backend::Cpu => Some("cpu"),
        Backend::Cuda => Some("cuda"),
        Backend::Wgpu => None,
    };
    let peer = match (&a.python, torch_device) {
        (Some(py), Some(torch_device)) => Some((py, torch_device)),
        (Some(_), None) => {
            println!("(PyTorch has no wgpu device: peer skipped)");
            None
        }
        (None, _) => {
            println!(
                "(no --python given: PyTorch peer skipped; bench/train_vs_pytorch.sh sets one up)"
            );
            None
        }
    };
    println!(
        "{:<10} {:<6} {:>14} {:>18} {:>17} {:>8} {:>15}",
        "design",
        "act",
        "nprt samples/s",
        "autodiff samples/s",
        "PyTorch samples/s",
        "ratio",
        "rounds' ratios"
    );
    for &arch in &a.designs.arch {
        let config = ModelConfig::new(arch, a.activation);
        let measure = |engine| {
            measure_throughput(
                &config,
                engine,
                a.batch_size,
                a.views,
                a.steps,
                a.warmup,
                &device,
            )
        };
        // Rounds alternate the peer and nprt, so that a drift in the machine's speed (identical
        // runs here differ by up to 30%) reaches both alike; medians are compared.
        let mut ours = Vec::new();
        let mut theirs = Vec::new();
        for _ in 0..rounds {
            if let Some((py, torch_device)) = peer {
                theirs.push(run_pytorch(py, &a, arch, threads, torch_device)?);
            }
            ours.push(measure(Engine::Auto));
        }
        let ratios: Vec<f64> = ours.iter().zip(&theirs).map(|(o, t)| o / t).collect();
        let ours = median(ours);
        // Off the CPU burn's autodiff is the only path, so the column would repeat the first.
        let autodiff = cpu.then(|| measure(Engine::Autodiff));
        let theirs = (!theirs.is_empty()).then(|| median(theirs));
        let spread = match ratios.iter().copied().reduce(f64::min) {
            Some(low) => {
                let high = ratios.iter().copied().fold(low, f64::max);
                format!("{low:.2}–{high:.2}×")
            }
            None => "-".into(),
        };
        println!(
            "{:<10} {:<6} {:>14.0} {:>18} {:>17} {:>8} {:>15}",
            arch.name(),
            config.activation.name(),
            ours,
            autodiff.map_or("-".into(), |t| format!("{t:.0}")),
            theirs.map_or("-".into(), |t| format!("{t:.0}")),
            theirs.map_or("-".into(), |t| format!("{:.2}×", ours / t)),
            spread
        );
    }
    Ok(())
}

/// Runs bench/train_pytorch.py for one design and returns its samples/s.
fn run_pytorch(
    python: &PathBuf,
    a: &BenchTrainArgs,
    design: Design,
    threads: usize,
    torch_device: &str,
) -> Result<f64> {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../bench/train_pytorch.py");
    let mut cmd = Process::new(python);
    cmd.arg(&script)
        .args(["--designs", design.name()])
        .args(["--batch-size", &a.batch_size.to_string()])
        .args(["--views", &a.views.to_string()])
        .args(["--steps", &a.steps.to_string()])
        .args(["--warmup", &a.warmup.to_string()])
        .args(["--threads", &threads.to_string()])
        .args(["--device", torch_device]);
    if let Some(act) = a.activation {
        cmd.args(["--activation", act.name()]);
    }
    let out = cmd
        .output()
        .with_context(|| format!("cannot run '{}'", python.display()))?;
    if !out.status.success() {
        bail!(
            "PyTorch peer failed: {}",
            String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("")
        );
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout
        .lines()
        .last()
        .context("PyTorch peer printed nothing")?;
    let v: serde_json::Value =
        serde_json::from_str(line).context("PyTorch peer printed non-JSON")?;
    v["samples_per_s"]
        .as_f64()
        .context("PyTorch peer printed no samples_per_s")
}
