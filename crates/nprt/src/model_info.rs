//! `nprt model info`: a design's layer table and parameter counts, or a trained model's; `nprt
//! model land`: a visit's model landed in a long run's folder.

use std::path::PathBuf;

use anyhow::{bail, Result};
use nprt_net::{Activation, Design, ModelSummary, PositionEncoding, DEFAULT_ENCODER_WIDTH};

use crate::flags::design_names;

#[derive(clap::Subcommand)]
pub enum ModelCommand {
    /// Print the layer table and parameter counts of a design (transport counts exclude the
    /// encoder, as the paper's Table 1).
    Info(ModelInfoArgs),
    /// Land a model folder a visit trained (bench/kitchen-visit.sh land) in a long run's folder:
    /// checked whole first (it loads, its checkpoint holds a validation loss, it continues the
    /// run's last visit), then RUN/model replaced as one folder and its row added to
    /// RUN/visits.csv, which is printed. Nothing in RUN changes when a check fails.
    Land(LandArgs),
}

#[derive(clap::Args)]
pub struct LandArgs {
    /// The model folder the visit brought back.
    model: PathBuf,
    /// The run's folder (pretrained/kitchen-dsep): its model/ and visits.csv.
    #[arg(long)]
    into: PathBuf,
    /// When the visit landed, UTC as YYYY-MM-DDTHH:MMZ (`date -u +%Y-%m-%dT%H:%MZ`).
    #[arg(long)]
    landed: String,
}

#[derive(clap::Args)]
pub struct ModelInfoArgs {
    /// Transport design (docs/model.md describes each; the paper's four are its Table 1).
    #[arg(long, required_unless_present = "model", conflicts_with = "model", value_parser = design_names())]
    arch: Option<Design>,
    /// A trained model folder: load it (checking its config and weights) and describe it.
    #[arg(long)]
    model: Option<PathBuf>,
    /// Activation of the layers that read the pixel inputs (siren or relu). Default: the
    /// paper's (relu for baseline, siren for the others).
    #[arg(long)]
    activation: Option<Activation>,
    /// Width W of the encoder's W × W/2 input map (a multiple of 64).
    #[arg(long, default_value_t = DEFAULT_ENCODER_WIDTH)]
    encoder_width: usize,
    /// Position input encoding: none (the paper) or hash-grid (its tables are listed with
    /// their parameters).
    #[arg(long, default_value_t = PositionEncoding::None)]
    encoding: PositionEncoding,
}

pub fn run(c: ModelCommand) -> Result<()> {
    match c {
        ModelCommand::Info(a) => info(a),
        ModelCommand::Land(a) => {
            let v = nprt_net::training::visits::land(&a.model, &a.into, &a.landed)?;
            println!(
                "{},{:.2},{},{},{:.5}",
                v.landed, v.gpu_minutes, v.samples, v.epochs, v.val_loss
            );
            Ok(())
        }
    }
}

fn info(a: ModelInfoArgs) -> Result<()> {
    let summary = match (&a.model, a.arch) {
        (Some(dir), _) => {
            let (file, summary) = ModelSummary::of_model(dir)?;
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
            summary
        }
        (None, Some(arch)) => {
            ModelSummary::of_design(arch, a.activation, a.encoder_width, a.encoding)?
        }
        (None, None) => bail!("give --arch or --model"),
    };
    print_description(&summary);
    Ok(())
}

fn print_description(s: &ModelSummary) {
    let config = &s.config;
    let light = match config.basis_in_use() {
        Some(b) => format!("light basis {b} on a"),
        None => "light encoder input".into(),
    };
    println!(
        "design {} ({} transport layers), {light} {}×{} map, map normalised by its {}, direct light {}, position encoding {}",
        config.design,
        config.activation,
        config.encoder_width,
        config.encoder_width / 2,
        match config.map_norm {
            nprt_net::MapNorm::Mean => "mean",
            nprt_net::MapNorm::Channel => "mean per channel",
        },
        match config.direct {
            nprt_net::DirectLight::Learned => "learned",
            nprt_net::DirectLight::Traced => "traced at run time",
        },
        config.encoding
    );
    println!("{:<24} {:<22} {:>10}", "layer", "shape", "params");
    for row in &s.layers {
        println!("{:<24} {:<22} {:>10}", row.name, row.shape, row.params);
    }
    let (paper, transport) = (s.paper_params, s.transport_params);
    let mb = |params: usize| params as f64 * 4.0 / 1e6;
    println!("encoder parameters:   {:>10}", s.encoder_params);
    let against = match paper {
        0 => "a design beyond the paper's Table 1".to_string(),
        _ => format!(
            "paper: {paper}, {:+.2}%",
            (transport as f64 / paper as f64 - 1.0) * 100.0
        ),
    };
    println!("transport parameters: {transport:>10} ({against})");
    if s.grid_entries > 0 {
        println!(
            "hash grid entries:    {:>10} ({:.2} MB as f32)",
            s.grid_entries,
            mb(s.grid_entries)
        );
    }
    println!(
        "total parameters:     {:>10} ({:.2} MB as f32)",
        s.total_params,
        mb(s.total_params)
    );
}
