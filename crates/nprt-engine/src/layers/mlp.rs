//! A multilayer perceptron with SIREN or ReLU hidden layers and their initialisations.

use crate::init::Init;
use crate::layers::activation::{Activation, OMEGA_0};
use crate::layers::dense::Dense;
use crate::parameters::{child, Parameters, Visit, VisitMut};

/// A multilayer perceptron: every layer but the last is followed by the activation; the last
/// one is linear. Also (same shapes) its gradient.
#[derive(Clone, Debug, PartialEq)]
pub struct Mlp {
    pub layers: Vec<Dense>,
    pub activation: Activation,
}

impl Mlp {
    /// `widths` lists the input width, the hidden widths and the output width.
    pub fn new(init: &mut Init, widths: &[usize], activation: Activation) -> Self {
        let layers = widths
            .windows(2)
            .enumerate()
            .map(|(i, w)| {
                let fan_in = w[0] as f32;
                let last = i + 2 == widths.len();
                let bound = match activation {
                    // He et al.'s uniform bound keeps the signal's variance through ReLU
                    // layers; PyTorch's nn.Linear default (1/√fan_in, kept for the linear
                    // output layer) shrinks it sixfold per layer, which left the deep baseline
                    // a near-constant function of its inputs (docs/model.md).
                    Activation::Relu if !last => (6.0 / fan_in).sqrt(),
                    Activation::Relu => 1.0 / fan_in.sqrt(),
                    Activation::Siren if i == 0 => 1.0 / fan_in,
                    Activation::Siren => (6.0 / fan_in).sqrt() / OMEGA_0,
                };
                Dense::new(init, w[0], w[1], bound)
            })
            .collect();
        Mlp { layers, activation }
    }

    /// (input, output) widths of each layer.
    pub fn shapes(&self) -> Vec<[usize; 2]> {
        self.layers.iter().map(|l| [l.d_in, l.d_out]).collect()
    }

    pub fn d_out(&self) -> usize {
        self.layers.last().map_or(0, |l| l.d_out)
    }
}

impl Parameters for Mlp {
    fn visit(&self, prefix: &str, f: &mut Visit) {
        self.layers.visit(&child(prefix, "layers"), f);
    }

    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut) {
        self.layers.visit_mut(&child(prefix, "layers"), f);
    }
}
