//! `nprt model info`: a design's layer table and parameter counts, or a trained model's.

use std::path::PathBuf;

use anyhow::{bail, Result};
use nprt_net::network::encoder::check_input_width;
use nprt_net::{
    layer_table, Activation, Design, Init, ModelConfig, NprtNet, PositionEncoding,
    DEFAULT_ENCODER_WIDTH,
};

#[derive(clap::Subcommand)]
pub enum ModelCommand {
    /// Print the layer table and parameter counts of a design (transport counts exclude the
    /// encoder, as the paper's Table 1).
    Info(ModelInfoArgs),
}

#[derive(clap::Args)]
pub struct ModelInfoArgs {
    /// Transport design: baseline, prt (PRT-inspired), albedo (albedo factorisation) or dsep
    /// (diffuse/specular separation).
    #[arg(long, required_unless_present = "model", conflicts_with = "model")]
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
    }
}

fn info(a: ModelInfoArgs) -> Result<()> {
    let (config, net) = match (&a.model, a.arch) {
        (Some(dir), _) => {
            let (file, net) = nprt_net::load_model(dir)?;
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
            check_input_width(a.encoder_width)?;
            let config = ModelConfig {
                encoder_width: a.encoder_width,
                encoding: a.encoding,
                ..ModelConfig::new(arch, a.activation)
            };
            let net = config.build(&mut Init::new(0));
            (config, net)
        }
        (None, None) => bail!("give --arch or --model"),
    };
    print_description(&config, &net);
    Ok(())
}

fn print_description(config: &ModelConfig, net: &NprtNet) {
    println!(
        "design {} ({} transport layers), light encoder input {}×{}, map normalised by its {}, direct light {}, position encoding {}",
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
    for row in layer_table(net) {
        println!("{:<24} {:<22} {:>10}", row.name, row.shape, row.params);
    }
    let transport = net.transport_params();
    let grid = net.grid_params();
    let encoder = net.total_params() - transport;
    let paper = config.design.paper_params();
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
}
