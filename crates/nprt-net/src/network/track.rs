//! One transport track of a design: an optional transfer network on the pixel inputs and the
//! shading network on the transport and light codes.

use crate::encoding::hash_grid::{self, HashGrid};
use crate::encoding::position_encoding::PositionEncoding;
use crate::init::Init;
use crate::network::activation::Activation;
use crate::network::design::{Design, Layout, TRANSPORT_CODE};
use crate::network::light_entry::LightEntry;
use crate::network::mlp::Mlp;
use crate::network::track_kind::TrackKind;
use crate::network::track_plan::{Net, TrackPlan};
use crate::parameters::{child, Parameters, Visit, VisitMut};

/// One transport track: an optional transfer network F_T on the pixel inputs, and the shading
/// network Φ on [ŝ, ê] (or, for the baseline, on [ê, inputs]; for the linear design on ŝ
/// alone, its outputs K transfer coefficients per term and channel). With a hash grid, the inputs
/// are followed by the grid's encoding of the position. Also (same shapes) its gradient; the
/// CPU engine runs it (`cpu::transport`).
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    pub grid: Option<HashGrid>,
    pub transfer: Option<Mlp>,
    pub shading: Mlp,
    pub kind: TrackKind,
    /// Where the light code enters: Φ's first layer (its outputs log-radiance), or the
    /// combine, Φ's outputs K transfer coefficients per term and channel at (term·K + k)·3 +
    /// channel, dotted with the code (the linear design).
    pub light: LightEntry,
}

impl Track {
    /// A track of `design` whose light code enters as `light` (one of [`Design::entries`]).
    pub fn new(
        init: &mut Init,
        design: Design,
        kind: TrackKind,
        activation: Activation,
        encoding: PositionEncoding,
        light: LightEntry,
    ) -> Self {
        let n_in = kind.inputs().len() + encoding.extra_inputs();
        let outputs = kind.outputs() * light.coefficients().max(1);
        let code = light.code_inputs();
        let grid = match encoding {
            PositionEncoding::None => None,
            PositionEncoding::HashGrid => Some(HashGrid::new(init)),
        };
        match design.spec().layout {
            Layout::Direct { hidden } => {
                let widths: Vec<usize> = std::iter::once(code + n_in)
                    .chain(hidden.iter().copied())
                    .chain([outputs])
                    .collect();
                Track {
                    grid,
                    transfer: None,
                    shading: Mlp::new(init, &widths, activation),
                    kind,
                    light,
                }
            }
            Layout::Transfer { width: w } => Track {
                grid,
                transfer: Some(Mlp::new(init, &[n_in, w, w, TRANSPORT_CODE], activation)),
                shading: Mlp::new(
                    init,
                    &[TRANSPORT_CODE + code, w, w, outputs],
                    Activation::Relu,
                ),
                kind,
                light,
            },
        }
    }
}

impl Track {
    /// Width of the first network's per-row input: the inputs read plus the grid's encoding.
    pub fn width(&self) -> usize {
        self.kind.inputs().len() + self.grid.as_ref().map_or(0, |_| hash_grid::OUTPUTS)
    }

    /// Its networks in the order they run ([`TrackPlan`]).
    pub fn plan(&self) -> TrackPlan {
        let transfer = self.transfer.as_ref().map(Mlp::d_out);
        TrackPlan::new(self.width(), transfer, self.shading.d_out(), self.light)
    }

    /// The network a step runs.
    pub fn mlp(&self, net: Net) -> &Mlp {
        match net {
            Net::Transfer => self.transfer.as_ref().expect("a transfer step has its network"),
            Net::Shading => &self.shading,
        }
    }

    /// The network a step runs, to change (a gradient's).
    pub fn mlp_mut(&mut self, net: Net) -> &mut Mlp {
        match net {
            Net::Transfer => self.transfer.as_mut().expect("a transfer step has its network"),
            Net::Shading => &mut self.shading,
        }
    }
}

impl Parameters for Track {
    fn visit(&self, prefix: &str, f: &mut Visit) {
        self.grid.visit(&child(prefix, "grid"), f);
        self.transfer.visit(&child(prefix, Net::Transfer.name()), f);
        self.shading.visit(&child(prefix, Net::Shading.name()), f);
    }

    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut) {
        self.grid.visit_mut(&child(prefix, "grid"), f);
        self.transfer.visit_mut(&child(prefix, Net::Transfer.name()), f);
        self.shading.visit_mut(&child(prefix, Net::Shading.name()), f);
    }
}
