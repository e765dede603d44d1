//! One transport track of a design: an optional transfer network on the pixel inputs and the
//! shading network on the transport and light codes.

use burn::module::Module;
use burn::tensor::{Int, Tensor, TensorData};

use crate::encoding::hash_grid::HashGrid;
use crate::encoding::position_encoding::PositionEncoding;
use crate::init::Init;
use crate::network::activation::Activation;
use crate::network::design::{Design, Layout, TRANSPORT_CODE};
use crate::network::encoder::CODE_SIZE;
use crate::network::mlp::Mlp;
use crate::network::track_kind::{TrackKind, Weight};

/// One transport track: an optional transfer network F_T on the pixel inputs, and the shading
/// network Φ on [ŝ, ê] (or, for the baseline, on [ê, inputs]). With a hash grid, the inputs
/// are followed by the grid's encoding of the position.
#[derive(Module, Debug)]
pub struct Track {
    pub grid: Option<HashGrid>,
    pub transfer: Option<Mlp>,
    pub shading: Mlp,
    #[module(skip)]
    pub kind: TrackKind,
}

impl Track {
    pub fn new(
        init: &mut Init,
        design: Design,
        kind: TrackKind,
        activation: Activation,
        encoding: PositionEncoding,
    ) -> Self {
        let n_in = kind.inputs().len() + encoding.extra_inputs();
        let outputs = kind.outputs();
        let grid = match encoding {
            PositionEncoding::None => None,
            PositionEncoding::HashGrid => Some(HashGrid::new(init)),
        };
        match design.spec().layout {
            Layout::Direct { hidden } => {
                let widths: Vec<usize> = std::iter::once(CODE_SIZE + n_in)
                    .chain(hidden.iter().copied())
                    .chain([outputs])
                    .collect();
                Track {
                    grid,
                    transfer: None,
                    shading: Mlp::new(init, &widths, activation),
                    kind,
                }
            }
            Layout::Transfer { width: w } => Track {
                grid,
                transfer: Some(Mlp::new(init, &[n_in, w, w, TRANSPORT_CODE], activation)),
                shading: Mlp::new(
                    init,
                    &[TRANSPORT_CODE + CODE_SIZE, w, w, outputs],
                    Activation::Relu,
                ),
                kind,
            },
        }
    }

    /// Radiance of this track (before the map's scale) for features [B, 19] and codes [B, 64].
    pub fn forward(&self, features: &Tensor<2>, code: &Tensor<2>) -> Tensor<2> {
        let inputs = if self.kind.reads_all() {
            features.clone()
        } else {
            let idx: Vec<i64> = self.kind.inputs().into_iter().map(|i| i as i64).collect();
            let n = idx.len();
            let idx = Tensor::<1, Int>::from_data(TensorData::new(idx, [n]), &features.device());
            features.clone().select(1, idx)
        };
        let inputs = match &self.grid {
            None => inputs,
            Some(grid) => Tensor::cat(vec![inputs, grid.forward(features)], 1),
        };
        let out = match &self.transfer {
            None => self
                .shading
                .forward(Tensor::cat(vec![code.clone(), inputs], 1)),
            Some(ft) => {
                let s = ft.forward(inputs);
                self.shading.forward(Tensor::cat(vec![s, code.clone()], 1))
            }
        };
        // The kind's terms (network/track_kind): each a weight times exp of three outputs.
        let terms = self.kind.spec().terms.iter().enumerate().map(|(k, w)| {
            let e = out.clone().narrow(1, 3 * k, 3).exp();
            match *w {
                Weight::One => e,
                Weight::Albedo(at) => features.clone().narrow(1, at, 3) * e,
            }
        });
        terms.reduce(|sum, t| sum + t).expect("a kind has terms")
    }
}
