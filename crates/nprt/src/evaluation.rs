//! `nprt eval` and `nprt train-deep-shading`.

use std::path::PathBuf;

use anyhow::{bail, Result};
use nprt_eval::{evaluate, write_report, EvalOptions, Evaluation};
use nprt_net::deep_shading::{self, DeepShadingOptions};
use nprt_net::{MapNorm, Schedule};
use nprt_render::DEFAULT_DIRECT_SPP;

use crate::{DeviceArg, RunLength};

#[derive(clap::Args)]
pub struct EvalArgs {
    /// Trained model folders (repeat the flag or separate with commas).
    #[arg(long, required = true, value_delimiter = ',')]
    pub model: Vec<PathBuf>,
    /// Dataset folder; its test views (held-out lighting) are evaluated.
    #[arg(long)]
    pub data: PathBuf,
    /// Report folder: report.md, report.html (self-contained), results.json, images/.
    #[arg(long)]
    pub out: PathBuf,
    /// A Deep Shading model folder (from `nprt train-deep-shading`) to compare too.
    #[arg(long)]
    pub deep_shading: Option<PathBuf>,
    /// Paths per pixel of the SH PRT transport precomputation.
    #[arg(long, default_value_t = 256)]
    pub sh_spp: u32,
    /// Side of the square frames of the timing table (the paper: 512).
    #[arg(long, default_value_t = 512)]
    pub timing_res: u32,
    /// Evaluate only the first N test views.
    #[arg(long)]
    pub views: Option<usize>,
    /// Test views shown as images (frames, crops, heat maps) in the report.
    #[arg(long, default_value_t = 3)]
    pub shown_views: usize,
    /// Seed of the baselines' path-traced samples (and of the traced direct light).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Samples per pixel of the direct light of models trained with `nprt train --direct
    /// traced`, traced per frame and counted in their time.
    #[arg(long, default_value_t = DEFAULT_DIRECT_SPP)]
    pub direct_spp: u32,
    #[command(flatten)]
    pub device: DeviceArg,
}

#[derive(clap::Args)]
pub struct DeepShadingArgs {
    /// Dataset folder made by `nprt generate`.
    #[arg(long)]
    pub data: PathBuf,
    /// Model folder; re-running with the same settings resumes exactly where the last run
    /// stopped (weights and Adam's moments), and a larger --epochs or --minutes continues a
    /// finished one (with --schedule paper).
    #[arg(long)]
    pub out: PathBuf,
    /// The run's length (--epochs: passes over the training views) and learning-rate schedule.
    #[command(flatten)]
    pub run: RunLength,
    /// Whole views per step.
    #[arg(long, default_value_t = DeepShadingOptions::default().batch_views)]
    pub batch_views: usize,
    /// Adam learning rate (1e-3 was measured to kill this ReLU U-Net: every activation dead,
    /// the output a constant).
    #[arg(long, default_value_t = DeepShadingOptions::default().schedule.learning_rate)]
    pub lr: f64,
    /// Seed of the initial weights and of the batch order.
    #[arg(long, default_value_t = DeepShadingOptions::default().schedule.seed)]
    pub seed: u64,
    /// Width W of the light encoder's W × W/2 input (a multiple of 64).
    #[arg(long, default_value_t = DeepShadingOptions::default().encoder_width)]
    pub encoder_width: usize,
    /// What the map is divided by for the encoder: channel (each channel's mean) or mean (one
    /// mean over channels), as `nprt train --map-norm`.
    #[arg(long, default_value_t = DeepShadingOptions::default().map_norm)]
    pub map_norm: MapNorm,
    #[command(flatten)]
    pub device: DeviceArg,
}

/// Runs the evaluation and writes the report; prints where it is and the headline figures.
pub fn eval(a: EvalArgs) -> Result<Evaluation> {
    if a.sh_spp == 0 || a.timing_res < 8 {
        bail!("--sh-spp must be at least 1 and --timing-res at least 8");
    }
    let opts = EvalOptions {
        data: a.data.clone(),
        models: a.model.clone(),
        deep_shading: a.deep_shading.clone(),
        sh_spp: a.sh_spp,
        timing_res: a.timing_res,
        max_views: a.views,
        shown_views: a.shown_views,
        seed: a.seed,
        direct_spp: a.direct_spp,
        progress: true,
    };
    let e = evaluate(&opts, &a.device.device()?)?;
    let (md, html) = write_report(&e, &a.out)?;
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

pub fn train_deep_shading(a: DeepShadingArgs) -> Result<()> {
    let defaults = DeepShadingOptions::default();
    let opts = DeepShadingOptions {
        schedule: a.run.apply(Schedule {
            learning_rate: a.lr,
            seed: a.seed,
            ..defaults.schedule
        }),
        batch_views: a.batch_views,
        encoder_width: a.encoder_width,
        map_norm: a.map_norm,
    };
    let (s, f) = deep_shading::train(&a.data, &opts, &a.out, &a.device.device()?)?;
    if let Some(e) = s.resumed_from_epoch {
        println!("resumed from epoch {e:.2}");
    }
    println!(
        "trained Deep Shading ({} U-Net parameters + {} encoder) for {} epochs in {:.1} s; training loss {:.5}, validation loss {:.5}; model in '{}'",
        f.unet_params,
        f.encoder_params,
        f.epochs_done,
        f.seconds,
        s.final_train,
        s.final_val,
        a.out.display()
    );
    println!("time: {}", s.split.describe());
    Ok(())
}
