//! What `nprt model info` (and `nprt.model_info` in Python) says of a network: every
//! parameterised layer with its shape and count, and the counts the paper's Table 1 compares.

use std::path::Path;

use anyhow::Result;
use serde::Serialize;

use crate::encoding::position_encoding::PositionEncoding;
use crate::init::Init;
use crate::model::config::ModelConfig;
use crate::model::folder::{load_model, ModelFile};
use crate::network::activation::Activation;
use crate::network::design::Design;
use crate::network::encoder::check_input_width;
use crate::network::light_model::LightModel;
use crate::network::nprt_net::NprtNet;
use crate::parameters::Parameters;

/// One row of `nprt model info`.
#[derive(Serialize)]
pub struct LayerRow {
    pub name: String,
    pub shape: String,
    pub params: usize,
}

/// Every parameterised layer of a network with its shape and parameter count.
pub fn layer_table(net: &NprtNet) -> Vec<LayerRow> {
    let mut rows = Vec::new();
    match &net.light {
        LightModel::Encoder(encoder) => {
            for (i, conv) in encoder.convs.iter().enumerate() {
                let (o, c, k) = (conv.c_out, conv.c_in, conv.k);
                rows.push(LayerRow {
                    name: format!("encoder.conv{i}"),
                    shape: format!("{c}→{o}, {k}×{k}"),
                    params: conv.num_params(),
                });
            }
            let (i, o) = (encoder.to_code.d_in, encoder.to_code.d_out);
            rows.push(LayerRow {
                name: "encoder.to_code".into(),
                shape: format!("{i}→{o}"),
                params: encoder.to_code.num_params(),
            });
        }
        LightModel::Basis(basis) => rows.push(LayerRow {
            name: format!("basis ({})", basis.choice),
            shape: format!(
                "{}×{} map → {} per channel",
                basis.width,
                basis.width / 2,
                basis.size()
            ),
            params: basis.num_params(),
        }),
    }
    for track in &net.tracks {
        let track_name = match net.tracks.len() {
            1 => String::new(),
            _ => format!("{:?}.", track.kind).to_lowercase(),
        };
        if let Some(grid) = &track.grid {
            use crate::encoding::hash_grid::{LEVELS, LEVEL_FEATURES, TABLE_SIZE};
            rows.push(LayerRow {
                name: format!("{track_name}grid"),
                shape: format!(
                    "{LEVELS} levels × 2^{} × {LEVEL_FEATURES}",
                    TABLE_SIZE.trailing_zeros()
                ),
                params: grid.num_params(),
            });
        }
        for step in track.plan().steps {
            let (part, mlp) = (step.net.name(), track.mlp(step.net));
            for (l, ([i, o], layer)) in mlp.shapes().into_iter().zip(&mlp.layers).enumerate() {
                let last = l + 1 == mlp.layers.len();
                let act = if last {
                    "linear"
                } else {
                    mlp.activation.name()
                };
                rows.push(LayerRow {
                    name: format!("{track_name}{part}.{l}"),
                    shape: format!("{i}→{o} {act}"),
                    params: layer.num_params(),
                });
            }
        }
    }
    rows
}

/// A network's layer table and parameter counts.
#[derive(Serialize)]
pub struct ModelSummary {
    pub config: ModelConfig,
    pub layers: Vec<LayerRow>,
    /// The light encoder's parameters.
    pub encoder_params: usize,
    /// The transport networks' parameters without hash-grid entries (as the paper's Table 1).
    pub transport_params: usize,
    /// The design's count in the paper's Table 1.
    pub paper_params: usize,
    /// Hash-grid entries (0 without a grid).
    pub grid_entries: usize,
    pub total_params: usize,
}

impl ModelSummary {
    /// A design's summary, untrained: `activation` None is the paper's for the design.
    pub fn of_design(
        design: Design,
        activation: Option<Activation>,
        encoder_width: usize,
        encoding: PositionEncoding,
    ) -> Result<Self> {
        check_input_width(encoder_width)?;
        let config = ModelConfig {
            encoder_width,
            encoding,
            ..ModelConfig::new(design, activation)
        };
        Ok(Self::new(&config, &config.build(&mut Init::new(0))))
    }

    /// A trained model folder's summary (its config and weights checked as loading does), and
    /// its model file.
    pub fn of_model(dir: &Path) -> Result<(ModelFile, Self)> {
        let (file, net) = load_model(dir)?;
        let summary = Self::new(&file.config, &net);
        Ok((file, summary))
    }

    pub fn new(config: &ModelConfig, net: &NprtNet) -> Self {
        let transport = net.transport_params();
        let grid = net.grid_params();
        ModelSummary {
            config: config.clone(),
            layers: layer_table(net),
            encoder_params: net.total_params() - transport,
            transport_params: transport - grid,
            paper_params: config.design.paper_params(),
            grid_entries: grid,
            total_params: net.total_params(),
        }
    }
}
