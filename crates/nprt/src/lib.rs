//! `nprt`: the command-line front end of the pipeline. It parses arguments, calls the stage
//! crates and reports; it owns no rendering, training or scene logic of its own, and states no
//! default that a library's options type states (one file per subcommand, shared flags in
//! `flags`). A library so that the Python package's `nprt` command runs the same command line
//! ([`main_with`]); the binary is main.rs.

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};

mod bake;
mod bench;
mod dataset;
mod demo;
mod eval;
mod export;
mod flags;
mod generate;
mod model_info;
mod paper;
mod reference;
mod render;
mod train;
mod train_deep_shading;
mod view;

#[derive(Parser)]
#[command(
    name = "nprt",
    version,
    args_override_self = true,
    about = "Neural precomputed radiance transfer: path-traced data, per-scene networks, relighting"
)]
struct Cli {
    /// Worker threads (default: all cores).
    #[arg(long, global = true)]
    threads: Option<usize>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// A scene and its lightings to a relit model in one resumable command: the dataset, the
    /// recommended recipe trained (a first relit frame in preview.png after its first minute),
    /// and a check against path tracing of equal cost on held-out views, under one progress
    /// bar; prints the model's errors and the commands that use it.
    Bake(bake::BakeArgs),
    /// Reproduce the paper's Tables 1-6 on a scene at a budget (tiny, small, medium, paper):
    /// one dataset, the four designs and Table 2's SIREN/ReLU ablation, Deep Shading, every
    /// baseline, then paper.md/paper.html with the paper's figures beside nprt's and each
    /// ordering it states judged. Resumable; docs/paper.md.
    Paper(paper::PaperArgs),
    /// Path-trace a scene through its own sensor and film (box pixel filter, the integrator's
    /// max_depth) and write every layer to one OpenEXR file; prints time and samples/s.
    Reference(reference::ReferenceArgs),
    /// The whole pipeline on the built-in scene and lighting: generate a dataset, train the four
    /// designs and Deep Shading, evaluate them against the baselines, relight a camera path
    /// under held-out lighting. About 15 minutes on 2 cores; --quick under a minute.
    Demo(demo::DemoArgs),
    /// Render a training dataset: G-buffers and radiance of many views under many lightings
    /// (documented in docs/dataset.md). Resumable; shards may run at once into one folder.
    Generate(generate::GenerateArgs),
    /// Inspect datasets.
    #[command(subcommand)]
    Dataset(dataset::DatasetCommand),
    /// Describe networks.
    #[command(subcommand)]
    Model(model_info::ModelCommand),
    /// Train one Neural PRT design (light encoder and transport, jointly) on a dataset; writes a
    /// model folder with weights, config, loss.csv, loss.png and a resumable checkpoint.
    Train(train::TrainArgs),
    /// Benchmarks.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// Relight a camera path with a trained model under a lighting schedule: primary rays for
    /// the G-buffer, the encoder once per lighting change, the network on foreground pixels.
    /// Writes PNG frames (EXR on request), an animation and per-frame timings.
    Render(render::RenderArgs),
    /// Evaluate trained designs against the paper's baselines (path tracing at 5 spp and at
    /// equal time, denoised when Open Image Denoise is installed, SH PRT with 9 and 25
    /// coefficients, Deep Shading) on a dataset's test views: metrics, error analysis, timings,
    /// images; writes a Markdown and a self-contained HTML report.
    Eval(eval::EvalArgs),
    /// Train the Deep Shading baseline (a per-scene U-Net on G-buffer images, with the light
    /// code at its bottleneck) on a dataset.
    TrainDeepShading(train_deep_shading::DeepShadingArgs),
    /// Write a trained model as an engine runs it: the GPU frame path's compute kernels (WGSL,
    /// with GLSL and HLSL translations) and its weights in a documented layout
    /// (docs/export.md). Needs the `gpu` feature.
    Export(export::ExportArgs),
    /// A window that relights trained models as you go: orbit (drag), dolly (wheel) and fly
    /// (WASDQE) the camera, turn the map (right-drag), switch maps (M) and models (Tab), a
    /// progressive path-traced reference of the view (R), the networks in f16 or f32 on the GPU
    /// kernels (F), traced direct light denoised or not (O), per-stage timings on screen, and
    /// screenshots (P). Needs the `gpu` feature and a display (Xvfb will do).
    View(view::ViewArgs),
}

/// Runs the command line `args` (the program's name first) as the `nprt` binary does: its
/// output and errors on stdout and stderr; returns the exit status (0, 1 for an error, 2 for
/// arguments clap refuses). Exits nothing itself, so an embedding interpreter lives on.
pub fn main_with<I, T>(args: I) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            // --help and --version come this way too, to stdout with status 0.
            let _ = e.print();
            return e.exit_code();
        }
    };
    let result = run(cli);
    nprt_net::finish();
    match result {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {}", nprt_io::describe_error(&e));
            1
        }
    }
}

/// Worker threads: `--threads`, else RAYON_NUM_THREADS (which rayon would read unchecked),
/// each held to the same bound; None for rayon's default (one per core).
fn worker_threads(flag: Option<usize>) -> Result<Option<usize>> {
    if let Some(n) = flag {
        nprt_io::check_threads(n, "--threads")?;
        return Ok(Some(n));
    }
    let Ok(value) = std::env::var("RAYON_NUM_THREADS") else {
        return Ok(None);
    };
    let n: usize = (value.trim().parse())
        .with_context(|| format!("RAYON_NUM_THREADS='{value}' is not a thread count"))?;
    if n == 0 {
        return Ok(None);
    }
    nprt_io::check_threads(n, "RAYON_NUM_THREADS")?;
    Ok(Some(n))
}

fn run(cli: Cli) -> Result<()> {
    if let Some(n) = worker_threads(cli.threads)? {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("cannot set up worker threads")?;
    }
    match cli.command {
        Command::Bake(a) => bake::command(a),
        Command::Reference(a) => reference::run(a),
        Command::Demo(a) => demo::run(a),
        Command::Paper(a) => paper::command(a),
        Command::Generate(a) => generate::run(&a.try_into()?),
        Command::Dataset(c) => dataset::run(c),
        Command::Model(c) => model_info::run(c),
        Command::Train(a) => train::command(a),
        Command::Bench(c) => bench::run(c),
        Command::Render(a) => render::command(a),
        Command::Eval(a) => eval::command(a),
        Command::TrainDeepShading(a) => train_deep_shading::command(a),
        Command::Export(a) => export::run(a),
        Command::View(a) => view::run(a),
    }
}
