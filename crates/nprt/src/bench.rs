//! `nprt bench train`, `infer` and `frame`: flags and tables; the measurements are
//! `nprt_net::bench` and `nprt_render::bench_frame`.

use std::path::PathBuf;

use anyhow::{Context, Result};
use nprt_net::bench::pytorch_peer::{PeerRun, PeerScript, PeerVariant};
use nprt_net::{
    measure_throughput, median, Activation, Design, DirectLight, Engine, ModelConfig, Precision,
};

use crate::flags::{design_names, DeviceArg, Resolution};

#[derive(clap::Subcommand)]
pub enum BenchCommand {
    /// Training samples/s of each design (forward, backward and Adam on one batch) on the CPU
    /// engine (or, with --device gpu or wgpu, nprt's own GPU kernels), beside the PyTorch peer (bench/train_pytorch.py,
    /// embedded in nprt) running the same networks, batch and loss when --python is given; the
    /// ratio is the engine's to the fastest of the PyTorch variants asked for.
    Train(BenchTrainArgs),
    /// Inference speed of each design's transport networks on the CPU engine at a square
    /// resolution, every pixel foreground: a frame from a new viewpoint, and a lighting change
    /// under a still camera (transfer outputs kept), with achieved GFLOP/s beside the machine's
    /// f32 peak (measured with register-resident FMA chains on as many threads).
    Infer(BenchInferArgs),
    /// What a relit frame costs, stage by stage (G-buffer, light encoder, networks, direct
    /// light), per design and resolution, with untrained networks (the cost does not depend on
    /// the weights): a frame from a new viewpoint under a new lighting, and a lighting change
    /// under a still camera. `--device gpu` (or `wgpu`) runs the networks as nprt's GPU
    /// kernels.
    Frame(BenchFrameArgs),
}

#[derive(clap::Args)]
pub struct BenchFrameArgs {
    #[command(flatten)]
    designs: BenchDesigns,
    /// Also time D/S with its direct light traced at run time (`--direct traced`), with this
    /// many samples per pixel; 0 leaves it out.
    #[arg(long, default_value_t = nprt_render::DEFAULT_DIRECT_SPP)]
    direct_spp: u32,
    /// Frame sizes, comma-separated, N or WxH (the paper's Table 3: 512; full HD 1920x1080).
    #[arg(long, default_value = "512,1920x1080", value_delimiter = ',')]
    res: Vec<Resolution>,
    /// The scene (one with a camera volume: a built-in, or a file with its NAME.camera.json).
    #[arg(long, default_value = "builtin:room")]
    scene: String,
    /// The lighting: an .exr/.hdr map or a built-in spec.
    #[arg(long, default_value = "builtin:sky:30:250:3")]
    map: String,
    /// Timed frames per measurement, after one untimed; the median is reported.
    #[arg(long, default_value_t = 5)]
    repeats: usize,
    /// Also print each kernel's GPU time in one lighting change (timestamp queries, each
    /// dispatch timed in a pass of its own) after each row: where the networks' time goes.
    /// Needs the GPU kernels (--device gpu or wgpu).
    #[arg(long)]
    profile: bool,
    /// The networks' arithmetic, comma-separated: f32, and f16 (weights and activations in
    /// f16, sums in f32, on tensor cores where the adapter has them; GPU kernels only), each
    /// timed as a row of its own.
    #[arg(long, default_value = "f32", value_delimiter = ',')]
    precision: Vec<Precision>,
    #[command(flatten)]
    device: DeviceArg,
}

/// The designs a benchmark measures.
#[derive(clap::Args)]
pub struct BenchDesigns {
    /// Designs to measure, comma-separated (default: the paper's four).
    #[arg(long, value_delimiter = ',', value_parser = design_names(), default_values_t = Design::PAPER)]
    arch: Vec<Design>,
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
}

#[derive(clap::Args)]
pub struct BenchTrainArgs {
    #[command(flatten)]
    designs: BenchDesigns,
    /// siren or relu (default: each design's own).
    #[arg(long)]
    activation: Option<Activation>,
    /// Samples per batch.
    #[arg(long, default_value_t = 16_384)]
    batch_size: usize,
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
    /// it runs on the same device (CUDA for the GPU kernels: the adapter is assumed to be an
    /// NVIDIA card PyTorch reaches through CUDA).
    #[arg(long)]
    python: Option<PathBuf>,
    /// How the peer runs, comma-separated: eager-f32, eager-bf16, compile-f32, compile-bf16
    /// (torch.compile; bf16: forward under bf16 autocast). Each is timed in every round; the
    /// fastest (by its median) is the peer compared with, and named in the last column.
    #[arg(long, value_delimiter = ',', default_value = "eager-f32")]
    peer_variants: Vec<PeerVariant>,
    /// With the GPU kernels (--device gpu or wgpu): after each design's row, the GPU time of each of nprt's kernels in
    /// one step after the warm-up (timestamp queries, each dispatch timed in a pass of its
    /// own), beside the step's wall time at the measured rate: where a step's time goes.
    #[arg(long)]
    profile: bool,
    /// The transport networks' products, comma-separated, a row each against the same peer:
    /// f32, and f16 (mixed precision: f16 operands summed in f32, on tensor cores where the
    /// adapter has them, f32 master weights; the GPU kernels only).
    #[arg(long, default_value = "f32", value_delimiter = ',')]
    precision: Vec<Precision>,
    #[command(flatten)]
    device: DeviceArg,
}

pub fn run(cmd: BenchCommand) -> Result<()> {
    match cmd {
        BenchCommand::Train(a) => train(a),
        BenchCommand::Infer(a) => infer(a),
        BenchCommand::Frame(a) => frame(a),
    }
}

/// Refuses `--profile` where nprt's own kernels do not run: the CPU, or a build without the
/// `gpu` feature.
fn check_profile(profile: bool, device: &DeviceArg) -> Result<()> {
    use nprt_net::Compute;
    anyhow::ensure!(
        !profile || matches!(device.compute, Compute::Gpu | Compute::Wgpu),
        "--profile times nprt's own kernels: it needs --device gpu or --device wgpu"
    );
    anyhow::ensure!(
        !profile || cfg!(feature = "gpu"),
        "--profile times nprt's own kernels: this nprt was built without the `gpu` feature"
    );
    Ok(())
}

fn frame(a: BenchFrameArgs) -> Result<()> {
    check_profile(a.profile, &a.device)?;
    let engine = a.device.engine()?;
    let mut models: Vec<(Design, DirectLight)> = a
        .designs
        .arch
        .iter()
        .map(|&d| (d, DirectLight::Learned))
        .collect();
    if a.direct_spp > 0 {
        models.push((Design::Dsep, DirectLight::Traced));
    }
    let opts = nprt_render::FrameBenchOptions {
        scene: a.scene,
        models,
        precisions: a.precision,
        profile: a.profile,
        resolutions: a.res.iter().map(|r| r.0).collect(),
        repeats: a.repeats.max(1),
        direct_spp: a.direct_spp,
        map: a.map,
    };
    let mut table = FrameTable::default();
    nprt_render::bench_frame(&opts, engine, |r| table.print(&opts, r))
}

/// `bench frame`'s table, printed a row at a time as the rows come: what was measured and the
/// columns before the first, the engine again where it changes (f16 rows after f32 ones).
#[derive(Default)]
struct FrameTable {
    /// Whether the header has been printed.
    headed: bool,
    networks_on: String,
}

impl FrameTable {
    fn print(&mut self, opts: &nprt_render::FrameBenchOptions, r: &nprt_render::FrameBenchRow) {
        let first = !self.headed;
        if first {
            println!(
            "relit frames of {} under {}, median of {} (ms; direct light traced {}, {} host threads)",
            opts.scene,
            opts.map,
            opts.repeats,
            r.paths_on,
            rayon::current_num_threads()
        );
        }
        if r.networks_on != self.networks_on {
            println!(
                "networks on the {}, G-buffer {}",
                r.networks_on, r.gbuffer_on
            );
            self.networks_on = r.networks_on.clone();
        }
        if first {
            println!(
                "{:<16} {:>10} {:>9} {:>9} {:>8} {:>9} {:>8} {:>9} {:>7} {:>11}",
                "design",
                "size",
                "pixels",
                "G-buffer",
                "encoder",
                "networks",
                "direct",
                "total",
                "fps",
                "relight ms"
            );
            self.headed = true;
        }
        let t = &r.frame;
        println!(
            "{:<16} {:>10} {:>9} {:>9.1} {:>8.1} {:>9.1} {:>8.1} {:>9.1} {:>7.2} {:>11.1}",
            r.label,
            format!("{}×{}", r.resolution[0], r.resolution[1]),
            r.foreground,
            t.gbuffer_ms,
            t.encoder_ms,
            t.network_ms,
            t.direct_ms,
            t.total_ms(),
            1e3 / t.total_ms(),
            r.relight_ms
        );
        if let Some(waits) = r.relight_waits {
            println!("  the host waited for the GPU {waits} time(s) in a lighting change");
        }
        if let Some([frame, change]) = r.shown_ms {
            println!(
                "  left on the device, as nprt view shows it (not read back): a new viewpoint \
             {frame:.1} ms ({:.1} fps), a lighting change {change:.1} ms ({:.1} fps)",
                1e3 / frame,
                1e3 / change
            );
        }
        #[cfg(feature = "gpu")]
        if let Some(times) = &r.profile {
            print_kernel_times("a lighting change's kernels", times, r.relight_ms);
        }
    }
}

/// The design column's width in the benches' tables: the longest design name.
fn design_column() -> usize {
    Design::ALL
        .iter()
        .map(|d| d.name().len())
        .max()
        .unwrap_or(0)
}

fn infer(a: BenchInferArgs) -> Result<()> {
    let p = nprt_net::cpu::measured_peak(rayon::current_num_threads());
    println!(
        "inference at {r}×{r} on the CPU engine, every pixel foreground, encoder not counted; \
         f32 peak {:.0} GFLOP/s ({} threads, {}-lane FMA chains, measured)",
        p.gflops,
        p.threads,
        p.lanes,
        r = a.resolution
    );
    println!(
        "{:<w$} {:>9} {:>8} {:>6} {:>11} {:>8} {:>6} {:>8}",
        "design",
        "frame ms",
        "GFLOP/s",
        "peak",
        "relight ms",
        "GFLOP/s",
        "peak",
        "speed-up",
        w = design_column()
    );
    for &arch in &a.designs.arch {
        let config = ModelConfig::new(arch, None);
        let s = nprt_net::measure_inference(&config, a.resolution * a.resolution, a.repeats);
        let pct = |g: f64| format!("{:.0}%", 100.0 * g / p.gflops);
        println!(
            "{:<w$} {:>9.1} {:>8.1} {:>6} {:>11.1} {:>8.1} {:>6} {:>7.2}×",
            arch.name(),
            s.frame_ms,
            s.frame_gflops,
            pct(s.frame_gflops),
            s.relight_ms,
            s.relight_gflops,
            pct(s.relight_gflops),
            s.frame_ms / s.relight_ms,
            w = design_column()
        );
    }
    Ok(())
}

fn train(a: BenchTrainArgs) -> Result<()> {
    check_profile(a.profile, &a.device)?;
    nprt_net::Batch::check_size(a.batch_size, a.views, nprt_net::DEFAULT_ENCODER_WIDTH)
        .context("--batch-size and --views")?;
    let threads = rayon::current_num_threads();
    let engine = a.device.engine()?;
    let rounds = a.rounds.max(1);
    println!(
        "training throughput on {}, batch {}, {} maps per batch, {} timed steps, {threads} threads, \
         median of {rounds} rounds",
        engine.name(),
        a.batch_size,
        a.views,
        a.steps
    );
    let peer = peer(a.python.as_ref(), engine)?;
    println!(
        "{:<w$} {:<6} {:<4} {:>14} {:>17} {:>8} {:>15}  peer",
        "design",
        "act",
        "prec",
        "nprt samples/s",
        "PyTorch samples/s",
        "ratio",
        "rounds' ratios",
        w = design_column()
    );
    for &arch in &a.designs.arch {
        let config = ModelConfig::new(arch, a.activation);
        let (ours, variants) = timed_rounds(&a, &config, peer.as_ref(), engine)?;
        let best = fastest(&variants);
        let theirs = best.map_or(Vec::new(), |v| variants[v].clone());
        for (&precision, ours) in a.precision.iter().zip(ours) {
            let ratios: Vec<f64> = ours.iter().zip(&theirs).map(|(o, t)| o / t).collect();
            let ours = median(ours);
            let theirs = (!theirs.is_empty()).then(|| median(theirs.clone()));
            let spread = ratio_range(&ratios);
            println!(
                "{:<w$} {:<6} {:<4} {:>14.0} {:>17} {:>8} {:>15}  {}",
                arch.name(),
                config.activation.name(),
                precision.name(),
                ours,
                theirs.map_or("-".into(), |t| format!("{t:.0}")),
                theirs.map_or("-".into(), |t| format!("{:.2}×", ours / t)),
                spread,
                best.map_or("-".into(), |v| a.peer_variants[v].name()),
                w = design_column()
            );
            if a.profile {
                print_profile(&config, &a, precision, 1e3 * a.batch_size as f64 / ours)?;
            }
        }
    }
    Ok(())
}

/// nprt's rate per precision and the peer's per variant, in each of the rounds `a` asks for,
/// training `config`. Rounds alternate the peer and nprt, so that a drift in the machine's speed
/// (identical runs here differ by up to 30%) reaches both alike; medians are compared.
fn timed_rounds(
    a: &BenchTrainArgs,
    config: &ModelConfig,
    peer: Option<&Peer>,
    engine: Engine,
) -> Result<(Vec<Rates>, Vec<Rates>)> {
    let mut ours = vec![Vec::new(); a.precision.len()];
    let mut variants = vec![Vec::new(); a.peer_variants.len()];
    for _ in 0..a.rounds.max(1) {
        if let Some((python, torch_device, script)) = peer {
            for (&variant, rates) in a.peer_variants.iter().zip(&mut variants) {
                rates.push(script.run(&PeerRun {
                    python,
                    design: config.design,
                    activation: a.activation,
                    batch_size: a.batch_size,
                    views: a.views,
                    steps: a.steps,
                    warmup: a.warmup,
                    threads: rayon::current_num_threads(),
                    torch_device,
                    variant,
                })?);
            }
        }
        for (&precision, rates) in a.precision.iter().zip(&mut ours) {
            let (batch, views, steps) = (a.batch_size, a.views, a.steps);
            rates.push(measure_throughput(
                config, batch, views, steps, a.warmup, precision, engine,
            )?);
        }
    }
    Ok((ours, variants))
}

/// Samples per second, one per round.
type Rates = Vec<f64>;

/// The PyTorch peer of a training bench: its Python, its torch device and its script.
type Peer<'a> = (&'a PathBuf, &'static str, PeerScript);

/// The fastest peer variant by its median rate, among those that ran.
fn fastest(variants: &[Vec<f64>]) -> Option<usize> {
    (0..variants.len())
        .filter(|&v| !variants[v].is_empty())
        .max_by(|&x, &y| median(variants[x].clone()).total_cmp(&median(variants[y].clone())))
}

/// "low–high×" of the rounds' ratios, or "-" without a peer.
fn ratio_range(ratios: &[f64]) -> String {
    match ratios.iter().copied().reduce(f64::min) {
        Some(low) => {
            let high = ratios.iter().copied().fold(low, f64::max);
            format!("{low:.2}–{high:.2}×")
        }
        None => "-".into(),
    }
}

/// The `--profile` lines of one design: its kernels' GPU time in one step, longest first.
#[cfg(feature = "gpu")]
fn print_profile(
    config: &ModelConfig,
    a: &BenchTrainArgs,
    precision: Precision,
    step_ms: f64,
) -> Result<()> {
    let times = nprt_net::profile_kernels(config, a.batch_size, a.views, a.warmup, precision)?;
    print_kernel_times("one step's kernels", &times, step_ms);
    Ok(())
}

/// `what`'s kernels' GPU times, longest first, beside the `wall_ms` it took at full speed.
#[cfg(feature = "gpu")]
fn print_kernel_times(what: &str, times: &[nprt_gpu::KernelTime], wall_ms: f64) {
    let sum: f64 = times.iter().map(|k| k.ms).sum();
    println!("  {what}: {sum:.2} ms of GPU time; wall time {wall_ms:.2} ms");
    for k in times {
        println!(
            "    {:<26} {:>4} × {:>9.3} ms {:>6.1}%",
            k.kernel,
            k.dispatches,
            k.ms,
            100.0 * k.ms / sum.max(f64::MIN_POSITIVE)
        );
    }
}

#[cfg(not(feature = "gpu"))]
fn print_profile(_: &ModelConfig, _: &BenchTrainArgs, _: Precision, _: f64) -> Result<()> {
    unreachable!("check_profile refuses --profile without the `gpu` feature")
}

/// The PyTorch peer to compare with, if one was given: its Python, PyTorch's device name (CUDA
/// for the GPU kernels) and the script written out.
fn peer(python: Option<&PathBuf>, engine: Engine) -> Result<Option<Peer<'_>>> {
    let torch_device = match engine {
        Engine::Cpu => "cpu",
        Engine::Gpu => "cuda",
    };
    Ok(match python {
        Some(py) => Some((py, torch_device, PeerScript::write()?)),
        None => {
            println!(
                "(no --python given: PyTorch peer skipped; bench/train_vs_pytorch.sh sets one up)"
            );
            None
        }
    })
}
