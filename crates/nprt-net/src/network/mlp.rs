//! A multilayer perceptron with SIREN or ReLU hidden layers and their initialisations.

use burn::module::Module;
use burn::nn::Linear;
use burn::tensor::activation::relu;
use burn::tensor::Tensor;

use crate::init::{dense, Init};
use crate::network::activation::{Activation, OMEGA_0};

/// A multilayer perceptron: every layer but the last is followed by the activation; the last
/// one is linear.
#[derive(Module, Debug)]
pub struct Mlp {
    pub layers: Vec<Linear>,
    #[module(skip)]
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
                dense(init, w[0], w[1], bound)
            })
            .collect();
        Mlp { layers, activation }
    }

    pub fn forward(&self, mut x: Tensor<2>) -> Tensor<2> {
        let last = self.layers.len() - 1;
        for (i, layer) in self.layers.iter().enumerate() {
            x = layer.forward(x);
            if i < last {
                x = match self.activation {
                    Activation::Siren => x.mul_scalar(OMEGA_0).sin(),
                    Activation::Relu => relu(x),
                };
            }
        }
        x
    }

    /// (input, output) widths of each layer.
    pub fn shapes(&self) -> Vec<[usize; 2]> {
        self.layers
            .iter()
            .map(|l| {
                let [i, o] = l.weight.val().dims();
                [i, o]
            })
            .collect()
    }
}
