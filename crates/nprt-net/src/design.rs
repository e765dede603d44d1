//! The four transport designs of the paper (its Table 1) and the whole network: encoder plus
//! transport.

use burn::module::Module;
use burn::tensor::{Int, Tensor, TensorData};
use serde::{Deserialize, Serialize};

use crate::encoder::{LightEncoder, CODE_SIZE};
use crate::layers::{Activation, Init, Mlp};

/// Floats per pixel: x (3, normalised), ωo (3), ωr (3), n (3), kd (3), ks (3), α (1).
pub const FEATURES: usize = 19;
/// Offsets of each input in the feature vector.
pub mod feature {
    use std::ops::Range;
    pub const POSITION: Range<usize> = 0..3;
    pub const VIEW: Range<usize> = 3..6;
    pub const MIRROR: Range<usize> = 6..9;
    pub const NORMAL: Range<usize> = 9..12;
    pub const KD: Range<usize> = 12..15;
    pub const KS: Range<usize> = 15..18;
    pub const ALPHA: Range<usize> = 18..19;
}

/// Size of the transport code ŝ.
pub const TRANSPORT_CODE: usize = 64;

/// The transport design (the paper's Table 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Design {
    /// One MLP on [ê, inputs]: 83 → 256 ×4 → 3.
    Baseline,
    /// PRT-inspired: F_T(inputs) = ŝ, then Φ(ŝ, ê) → radiance.
    Prt,
    /// As PRT, but Φ outputs L^D and L^S and L = kd·L^D + ks·L^S.
    Albedo,
    /// Two tracks of width 172: diffuse F_T^D(x, n, kd) and specular F_T^S(x, n, ks, ωo, ωr, α),
    /// each with its own Φ; L = kd·Φ^D + ks·Φ^S.
    Dsep,
}

impl Design {
    pub const ALL: [Design; 4] = [Design::Baseline, Design::Prt, Design::Albedo, Design::Dsep];

    pub fn name(self) -> &'static str {
        match self {
            Design::Baseline => "baseline",
            Design::Prt => "prt",
            Design::Albedo => "albedo",
            Design::Dsep => "dsep",
        }
    }

    /// Transport parameter count the paper gives (Table 1).
    pub fn paper_params(self) -> usize {
        match self {
            Design::Baseline => 219_651,
            Design::Prt => 186_947,
            Design::Albedo => 187_718,
            Design::Dsep => 194_226,
        }
    }

    /// The paper's activation for the layers that see the pixel inputs: ReLU for the baseline,
    /// SIREN for the transport networks F_T of the other designs.
    pub fn default_activation(self) -> Activation {
        match self {
            Design::Baseline => Activation::Relu,
            _ => Activation::Siren,
        }
    }
}

impl std::str::FromStr for Design {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Design::ALL
            .into_iter()
            .find(|d| d.name() == s)
            .ok_or_else(|| format!("unknown design '{s}' (expected baseline, prt, albedo or dsep)"))
    }
}

/// Which pixel inputs a track reads, and how its outputs weight into radiance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackKind {
    /// All 19 inputs; outputs are radiance.
    Full,
    /// All 19 inputs; 6 outputs, kd·exp(first 3) + ks·exp(last 3).
    Albedo,
    /// x, n, kd; weighted by kd.
    Diffuse,
    /// x, n, ks, ωo, ωr, α; weighted by ks.
    Specular,
}

impl TrackKind {
    fn inputs(self) -> Vec<usize> {
        use feature::*;
        match self {
            TrackKind::Full | TrackKind::Albedo => (0..FEATURES).collect(),
            TrackKind::Diffuse => [POSITION, NORMAL, KD].into_iter().flatten().collect(),
            TrackKind::Specular => [POSITION, NORMAL, KS, VIEW, MIRROR, ALPHA]
                .into_iter()
                .flatten()
                .collect(),
        }
    }
}

/// One transport track: an optional transfer network F_T on the pixel inputs, and the shading
/// network Φ on [ŝ, ê] (or, for the baseline, on [ê, inputs]).
#[derive(Module, Debug)]
pub struct Track {
    pub transfer: Option<Mlp>,
    pub shading: Mlp,
    #[module(skip)]
    pub kind: TrackKind,
}

impl Track {
    fn new(init: &mut Init, design: Design, kind: TrackKind, activation: Activation) -> Self {
        let n_in = kind.inputs().len();
        let outputs = if kind == TrackKind::Albedo { 6 } else { 3 };
        match design {
            Design::Baseline => Track {
                transfer: None,
                shading: Mlp::new(init, &[CODE_SIZE + n_in, 256, 256, 256, 256, 3], activation),
                kind,
            },
            _ => {
                let w = if design == Design::Dsep { 172 } else { 256 };
                Track {
                    transfer: Some(Mlp::new(init, &[n_in, w, w, TRANSPORT_CODE], activation)),
                    shading: Mlp::new(
                        init,
                        &[TRANSPORT_CODE + CODE_SIZE, w, w, outputs],
                        Activation::Relu,
                    ),
                    kind,
                }
            }
        }
    }

    /// Radiance of this track (before the map's scale) for features [B, 19] and codes [B, 64].
    fn forward(&self, features: &Tensor<2>, code: &Tensor<2>) -> Tensor<2> {
        let inputs = if self.kind == TrackKind::Full || self.kind == TrackKind::Albedo {
            features.clone()
        } else {
            let idx: Vec<i64> = self.kind.inputs().into_iter().map(|i| i as i64).collect();
            let n = idx.len();
            let idx = Tensor::<1, Int>::from_data(TensorData::new(idx, [n]), &features.device());
            features.clone().select(1, idx)
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
        // Outputs are log-radiance: exp keeps radiance positive over its high dynamic range.
        let slice = |r: std::ops::Range<usize>| features.clone().narrow(1, r.start, r.len());
        match self.kind {
            TrackKind::Full => out.exp(),
            TrackKind::Albedo => {
                slice(feature::KD) * out.clone().narrow(1, 0, 3).exp()
                    + slice(feature::KS) * out.narrow(1, 3, 3).exp()
            }
            TrackKind::Diffuse => slice(feature::KD) * out.exp(),
            TrackKind::Specular => slice(feature::KS) * out.exp(),
        }
    }
}

/// Encoder plus transport: G-buffer features and a light code in, radiance out.
#[derive(Module, Debug)]
pub struct NprtNet {
    pub encoder: LightEncoder,
    pub tracks: Vec<Track>,
}

impl NprtNet {
    pub fn new(
        init: &mut Init,
        design: Design,
        activation: Activation,
        encoder_width: usize,
    ) -> Self {
        let encoder = LightEncoder::new(init, encoder_width);
        let kinds: &[TrackKind] = match design {
            Design::Baseline | Design::Prt => &[TrackKind::Full],
            Design::Albedo => &[TrackKind::Albedo],
            Design::Dsep => &[TrackKind::Diffuse, TrackKind::Specular],
        };
        let tracks = kinds
            .iter()
            .map(|&k| Track::new(init, design, k, activation))
            .collect();
        NprtNet { encoder, tracks }
    }

    /// Radiance [B, 3] for features [B, 19] lit by codes [B, 64] of maps whose means are
    /// `scale` [B, 1].
    pub fn shade(&self, features: Tensor<2>, code: Tensor<2>, scale: Tensor<2>) -> Tensor<2> {
        let radiance = self
            .tracks
            .iter()
            .map(|t| t.forward(&features, &code))
            .reduce(|a, b| a + b)
            .expect("a design has at least one track");
        radiance * scale
    }

    /// Radiance for a batch mixing views: `light` holds the V pre-processed maps [V, 3, H, W],
    /// `view` [B] says which map lights each sample and `scale` [B, 1] is that map's mean.
    pub fn forward(
        &self,
        features: Tensor<2>,
        light: Tensor<4>,
        view: Tensor<1, Int>,
        scale: Tensor<2>,
    ) -> Tensor<2> {
        let code = self.encoder.forward(light).select(0, view);
        self.shade(features, code, scale)
    }

    pub fn total_params(&self) -> usize {
        self.num_params()
    }

    /// Transport parameters: everything but the encoder (the paper's counts).
    pub fn transport_params(&self) -> usize {
        self.tracks.iter().map(|t| t.num_params()).sum()
    }
}
