//! `nprt train-deep-shading`: flags for training the Deep Shading baseline; the work is
//! `nprt_net::deep_shading::train`.

use std::path::PathBuf;

use anyhow::Result;
use nprt_net::deep_shading::{self, DeepShadingOptions};
use nprt_net::{Engine, MapNorm, Schedule};

use crate::flags::{DeviceArg, RunArgs};

/// The defaults every flag shows, from the one place that states them.
fn d() -> DeepShadingOptions {
    DeepShadingOptions::default()
}

#[derive(clap::Args)]
pub struct DeepShadingArgs {
    /// Dataset folder made by `nprt generate`.
    #[arg(long)]
    data: PathBuf,
    /// Model folder; re-running with the same settings resumes exactly where the last run
    /// stopped (weights and Adam's moments), and a larger --epochs or --minutes continues a
    /// finished one (with --schedule paper).
    #[arg(long)]
    out: PathBuf,
    /// The run's length (--epochs: passes over the training views) and learning-rate schedule.
    #[command(flatten)]
    run: RunArgs,
    /// Whole views per step.
    #[arg(long, default_value_t = d().batch_views)]
    batch_views: usize,
    /// Adam learning rate (1e-3 was measured to kill this ReLU U-Net: every activation dead,
    /// the output a constant).
    #[arg(long, value_parser = crate::flags::finite_f64, default_value_t = d().schedule.learning_rate)]
    lr: f64,
    /// Seed of the initial weights and of the batch order.
    #[arg(long, default_value_t = d().schedule.seed)]
    seed: u64,
    /// Width W of the light encoder's W × W/2 input (a multiple of 64).
    #[arg(long, default_value_t = d().encoder_width)]
    encoder_width: usize,
    /// What the map is divided by for the encoder: channel (each channel's mean) or mean (one
    /// mean over channels), as `nprt train --map-norm`.
    #[arg(long, default_value_t = d().map_norm)]
    map_norm: MapNorm,
    #[command(flatten)]
    device: DeviceArg,
}

/// One Deep Shading training run as the library takes it.
pub struct DeepShadingJob {
    pub data: PathBuf,
    pub opts: DeepShadingOptions,
    pub out: PathBuf,
    pub engine: Engine,
}

impl TryFrom<DeepShadingArgs> for DeepShadingJob {
    type Error = anyhow::Error;

    fn try_from(a: DeepShadingArgs) -> Result<Self> {
        let defaults = DeepShadingOptions::default();
        let run: nprt_net::RunLength = a.run.into();
        Ok(DeepShadingJob {
            engine: a.device.engine()?,
            data: a.data,
            opts: DeepShadingOptions {
                schedule: run.apply(Schedule {
                    learning_rate: a.lr,
                    seed: a.seed,
                    ..defaults.schedule
                }),
                batch_views: a.batch_views,
                encoder_width: a.encoder_width,
                map_norm: a.map_norm,
            },
            out: a.out,
        })
    }
}

pub fn command(a: DeepShadingArgs) -> Result<()> {
    run(&a.try_into()?)
}

/// Trains and prints what the run did.
pub fn run(job: &DeepShadingJob) -> Result<()> {
    let (s, f) = deep_shading::train(
        &job.data,
        &job.opts,
        job.engine,
        &job.out,
        nprt_net::Watch::default(),
    )?;
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
        job.out.display()
    );
    println!("time: {} (steps on {})", s.split.describe(), s.steps_on);
    Ok(())
}
