//! The whole network: light encoder plus a design's transport tracks.

use burn::module::Module;
use burn::tensor::{Int, Tensor};

use crate::encoding::position_encoding::PositionEncoding;
use crate::init::{shifted_bias, Init};
use crate::network::activation::Activation;
use crate::network::design::Design;
use crate::network::encoder::LightEncoder;
use crate::network::track::Track;

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
        encoding: PositionEncoding,
    ) -> Self {
        let encoder = LightEncoder::new(init, encoder_width);
        let tracks = (design.spec().tracks.iter())
            .map(|&k| Track::new(init, design, k, activation, encoding))
            .collect();
        NprtNet { encoder, tracks }
    }

    /// Radiance [B, 3] for features [B, 19] lit by codes [B, 64] of maps normalised by
    /// `scale` [B, 3].
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
    /// `view` [B] says which map lights each sample and `scale` [B, 3] is what that map was
    /// divided by.
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

    /// Adds `log_level` to every track's output bias, so that an untrained network predicts
    /// radiance of about exp(`log_level`) × the map's mean. Starting at the data's level
    /// matters where it is far from the map's mean (a room lit through a window gets a small
    /// fraction of its map): started orders of magnitude too bright, the exp output's first
    /// steps overshoot to near zero, where log-L1's gradient (∝ the prediction) vanishes and
    /// Adam, still scaled by the first steps' huge gradients, never brings it back. The
    /// shifted bias is a fresh leaf, so autodiff trains it as any parameter.
    pub fn shift_output_level(mut self, log_level: f32) -> Self {
        for track in &mut self.tracks {
            let last = track
                .shading
                .layers
                .last_mut()
                .expect("a network has layers");
            last.bias = shifted_bias(last.bias.take(), log_level);
        }
        self
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
