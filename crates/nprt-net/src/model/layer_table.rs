//! The layer table of `nprt model info`: every parameterised layer with its shape and count.

use crate::network::nprt_net::NprtNet;
use crate::network::parameters::Parameters;

/// One row of `nprt model info`.
pub struct LayerRow {
    pub name: String,
    pub shape: String,
    pub params: usize,
}

/// Every parameterised layer of a network with its shape and parameter count.
pub fn layer_table(net: &NprtNet) -> Vec<LayerRow> {
    let mut rows = Vec::new();
    for (i, conv) in net.encoder.convs.iter().enumerate() {
        let (o, c, k) = (conv.c_out, conv.c_in, conv.k);
        rows.push(LayerRow {
            name: format!("encoder.conv{i}"),
            shape: format!("{c}→{o}, {k}×{k}"),
            params: conv.num_params(),
        });
    }
    let (i, o) = (net.encoder.to_code.d_in, net.encoder.to_code.d_out);
    rows.push(LayerRow {
        name: "encoder.to_code".into(),
        shape: format!("{i}→{o}"),
        params: net.encoder.to_code.num_params(),
    });
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
        let parts = [
            ("transfer", track.transfer.as_ref()),
            ("shading", Some(&track.shading)),
        ];
        for (part, mlp) in parts {
            let Some(mlp) = mlp else { continue };
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
