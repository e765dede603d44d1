//! The whole network: light model (encoder or basis) plus a design's transport tracks.

use crate::encoding::position_encoding::PositionEncoding;
use crate::init::Init;
use crate::network::activation::Activation;
use crate::network::design::Design;
use crate::network::encoder::LightEncoder;
use crate::network::light_basis::{BasisChoice, LightBasis};
use crate::network::light_entry::LightEntry;
use crate::network::light_model::LightModel;
use crate::network::track::Track;
use crate::parameters::{child, Parameters, Visit, VisitMut};

/// Light model plus transport: G-buffer features and a light code in, radiance out. Also (same
/// shapes) its gradient. The CPU engine runs it (`cpu`), the GPU kernels from its values.
#[derive(Clone, Debug, PartialEq)]
pub struct NprtNet {
    pub light: LightModel,
    pub tracks: Vec<Track>,
}

impl NprtNet {
    pub fn new(
        init: &mut Init,
        design: Design,
        activation: Activation,
        encoder_width: usize,
        encoding: PositionEncoding,
        basis: BasisChoice,
    ) -> Self {
        let light = match design.reads_basis() {
            true => LightModel::Basis(LightBasis::new(init, basis, encoder_width)),
            false => LightModel::Encoder(LightEncoder::new(init, encoder_width)),
        };
        let kinds = design.spec().tracks.iter();
        let tracks = (kinds.zip(design.entries(basis.size())))
            .map(|(&k, entry)| Track::new(init, design, k, activation, encoding, entry))
            .collect();
        NprtNet { light, tracks }
    }

    /// Adds `log_level` to every track's output bias, so that an untrained network predicts
    /// radiance of about exp(`log_level`) × the map's mean. Starting at the data's level
    /// matters where it is far from the map's mean (a room lit through a window gets a small
    /// fraction of its map): started orders of magnitude too bright, the exp output's first
    /// steps overshoot to near zero, where log-L1's gradient (∝ the prediction) vanishes and
    /// Adam, still scaled by the first steps' huge gradients, never brings it back.
    ///
    /// A linear track's outputs are transfer coefficients, not log-radiance: its first
    /// coefficient (the constant function's, which a map of mean 1 projects to about √(4π)) is
    /// raised instead, so that the tracks together start at the level, weighted by albedos of
    /// about one half.
    pub fn shift_output_level(mut self, log_level: f32) -> Self {
        let tracks = self.tracks.len() as f32;
        for track in &mut self.tracks {
            let last = track
                .shading
                .layers
                .last_mut()
                .expect("a network has layers");
            match track.light {
                LightEntry::FirstLayer { .. } => last.bias.iter_mut().for_each(|b| *b += log_level),
                LightEntry::Combine { k } => {
                    let constant = (4.0 * std::f32::consts::PI).sqrt();
                    let t0 = log_level.exp() / (tracks * constant * 0.5);
                    for term in last.bias.chunks_exact_mut(3 * k) {
                        term[..3].iter_mut().for_each(|b| *b += t0);
                    }
                }
            }
        }
        self
    }

    /// The convolutional encoder, for the engines that run only it (see
    /// [`LightModel::encoder`]).
    pub fn encoder(&self) -> anyhow::Result<&LightEncoder> {
        self.light.encoder()
    }

    pub fn total_params(&self) -> usize {
        self.num_params()
    }

    /// Transport parameters: everything but the encoder (the paper's counts, plus a hash
    /// grid's tables where there is one).
    pub fn transport_params(&self) -> usize {
        self.tracks.iter().map(|t| t.num_params()).sum()
    }

    /// The hash grids' table entries (none for the paper's inputs).
    pub fn grid_params(&self) -> usize {
        self.tracks
            .iter()
            .filter_map(|t| t.grid.as_ref())
            .map(|g| g.num_params())
            .sum()
    }
}

impl Parameters for NprtNet {
    fn visit(&self, prefix: &str, f: &mut Visit) {
        self.light.visit(prefix, f);
        self.tracks.visit(&child(prefix, "tracks"), f);
    }

    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut) {
        self.light.visit_mut(prefix, f);
        self.tracks.visit_mut(&child(prefix, "tracks"), f);
    }
}
