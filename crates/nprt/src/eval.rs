//! `nprt eval`: flags for evaluating models against the baselines; the work is
//! `nprt_eval::evaluate` and `write_report`.

use std::path::PathBuf;

use anyhow::Result;
use nprt_eval::{evaluate, write_report, EvalOptions, Evaluation};
use nprt_net::Engine;

use crate::flags::DeviceArg;

/// The defaults every flag shows, from the one place that states them.
fn d() -> EvalOptions {
    EvalOptions::default()
}

#[derive(clap::Args)]
pub struct EvalArgs {
    /// Trained model folders (repeat the flag or separate with commas).
    #[arg(long, required = true, value_delimiter = ',')]
    model: Vec<PathBuf>,
    /// Dataset folder; its test views (held-out lighting) are evaluated.
    #[arg(long)]
    data: PathBuf,
    /// Report folder: report.md, report.html (self-contained), results.json, images/.
    #[arg(long)]
    out: PathBuf,
    /// A Deep Shading model folder (from `nprt train-deep-shading`) to compare too.
    #[arg(long)]
    deep_shading: Option<PathBuf>,
    /// Paths per pixel of the SH PRT transport precomputation.
    #[arg(long, default_value_t = d().sh_spp)]
    sh_spp: u32,
    /// Side of the square frames of the timing table (the paper: 512).
    #[arg(long, default_value_t = d().timing_res)]
    timing_res: u32,
    /// Evaluate only the first N test views.
    #[arg(long)]
    views: Option<usize>,
    /// Test views shown as images (frames, crops, heat maps) in the report.
    #[arg(long, default_value_t = d().shown_views)]
    shown_views: usize,
    /// Seed of the baselines' path-traced samples (and of the traced direct light).
    #[arg(long, default_value_t = d().seed)]
    seed: u64,
    /// Samples per pixel of the direct light of models trained with `nprt train --direct
    /// traced`, traced per frame and counted in their time.
    #[arg(long, default_value_t = d().direct_spp)]
    direct_spp: u32,
    /// Frames of the temporal evaluation: every method along a slow camera move through the
    /// scene's camera volume, the lighting changing from one held-out map to another half-way,
    /// scored frame to frame against path-traced references at the dataset's test spp (0 skips
    /// it).
    #[arg(long, default_value_t = d().temporal_frames)]
    temporal_frames: usize,
    /// Side of the temporal evaluation's square frames.
    #[arg(long, default_value_t = d().temporal_res)]
    temporal_res: u32,
    /// The Neural Radiance Cache baselines (NRC, NRC-CACHE) run along the temporal path from
    /// a cold start, and again after rendering this many frames at its first frame (0: cold
    /// only).
    #[arg(long, default_value_t = d().nrc_warmup)]
    nrc_warmup: usize,
    /// Also score where each traced model's error lives: its network's indirect light with
    /// the reference's direct light, and its traced direct light (denoised where OIDN is
    /// installed) with the reference's indirect light, as rows of their own (measurements: no
    /// time, no equal-time peer).
    #[arg(long)]
    oracles: bool,
    #[command(flatten)]
    device: DeviceArg,
}

/// An evaluation and where its report goes.
pub struct EvalJob {
    pub opts: EvalOptions,
    pub out: PathBuf,
}

impl From<EvalArgs> for EvalJob {
    fn from(a: EvalArgs) -> Self {
        EvalJob {
            opts: EvalOptions {
                data: a.data,
                models: a.model,
                deep_shading: a.deep_shading,
                sh_spp: a.sh_spp,
                timing_res: a.timing_res,
                max_views: a.views,
                shown_views: a.shown_views,
                seed: a.seed,
                direct_spp: a.direct_spp,
                temporal_frames: a.temporal_frames,
                temporal_res: a.temporal_res,
                nrc_warmup: a.nrc_warmup,
                oracles: a.oracles,
                progress: true,
            },
            out: a.out,
        }
    }
}

pub fn command(a: EvalArgs) -> Result<()> {
    let engine = a.device.engine()?;
    run(&a.into(), engine).map(|_| ())
}

/// Runs the evaluation and writes the report; prints where it is and the headline figures.
pub fn run(job: &EvalJob, engine: Engine) -> Result<Evaluation> {
    let direct = format!(
        "{} spp; denoised by OIDN in its '+ OIDN' row where OIDN is installed",
        job.opts.direct_spp
    );
    for dir in &job.opts.models {
        let file = nprt_net::read_model_file(dir)?;
        println!("model '{}': {}", dir.display(), file.describe(&direct));
    }
    let e = evaluate(&job.opts, engine)?;
    let (md, html) = write_report(&e, &job.out)?;
    println!(
        "{:<32} {:>10} {:>10} {:>10} {:>12}",
        "method", "L1", "RMSE", "dSSIM", "ms / view"
    );
    for m in &e.methods {
        println!(
            "{:<32} {:>10.5} {:>10.5} {:>10.5} {:>12.1}",
            m.name, m.mean.l1, m.mean.rmse, m.mean.dssim, m.ms_per_view
        );
    }
    if let Some(f) = &e.noise_floor {
        println!(
            "{:<32} {:>10.5} {:>10.5} {:>10.5} {:>12}",
            format!("reference noise ({} spp)", e.reference_spp),
            f.l1,
            f.rmse,
            f.dssim,
            "–"
        );
    }
    for c in e.checks() {
        println!("{:<13} {}", format!("{}:", c.verdict.word()), c.text);
    }
    println!("report: {} and {}", md.display(), html.display());
    Ok(e)
}
