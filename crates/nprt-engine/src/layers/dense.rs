//! One dense layer's weights: `y = x·W + b`, W row-major `d_in × d_out` (as the model file
//! stores it).

use crate::init::Init;
use crate::parameters::{child, Parameters, Visit, VisitMut};

/// One dense layer, or (same shapes) its gradient.
#[derive(Clone, Debug, PartialEq)]
pub struct Dense {
    pub weight: Vec<f32>,
    pub bias: Vec<f32>,
    pub d_in: usize,
    pub d_out: usize,
}

impl Dense {
    /// W uniform in ±`weight_bound` (chosen by the caller); the bias takes PyTorch's default
    /// bound 1/√fan_in, as Sitzmann et al.'s reference code keeps it.
    pub fn new(init: &mut Init, d_in: usize, d_out: usize, weight_bound: f32) -> Self {
        let bias_bound = 1.0 / (d_in as f32).sqrt();
        Dense {
            weight: init.uniform(d_in * d_out, weight_bound),
            bias: init.uniform(d_out, bias_bound),
            d_in,
            d_out,
        }
    }
}

impl Parameters for Dense {
    fn visit(&self, prefix: &str, f: &mut Visit) {
        f(
            &child(prefix, "weight"),
            &[self.d_in, self.d_out],
            &self.weight,
        );
        f(&child(prefix, "bias"), &[self.d_out], &self.bias);
    }

    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut) {
        let shape = [self.d_in, self.d_out];
        f(&child(prefix, "weight"), &shape, &mut self.weight);
        f(&child(prefix, "bias"), &[self.d_out], &mut self.bias);
    }
}
