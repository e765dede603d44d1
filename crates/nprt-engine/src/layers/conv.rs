//! One k×k convolution's weights with "same" zero padding: `weight` is
//! [c_out, c_in, k, k], read as a row-major c_out × (c_in · k²) matrix by the engines.

use crate::init::Init;
use crate::parameters::{child, Parameters, Visit, VisitMut};

/// One convolution, or (same shapes) its gradient.
#[derive(Clone, Debug, PartialEq)]
pub struct Conv {
    pub weight: Vec<f32>,
    pub bias: Vec<f32>,
    pub c_in: usize,
    pub c_out: usize,
    /// The kernel's side: 3, or 1 for a per-pixel layer.
    pub k: usize,
}

impl Conv {
    /// PyTorch's default initialisation: U(±1/√fan_in) for weight and bias.
    pub fn new(init: &mut Init, c_in: usize, c_out: usize, k: usize) -> Self {
        let bound = 1.0 / ((c_in * k * k) as f32).sqrt();
        Conv {
            weight: init.uniform(c_out * c_in * k * k, bound),
            bias: init.uniform(c_out, bound),
            c_in,
            c_out,
            k,
        }
    }

    fn shape(&self) -> [usize; 4] {
        [self.c_out, self.c_in, self.k, self.k]
    }
}

impl Parameters for Conv {
    fn visit(&self, prefix: &str, f: &mut Visit) {
        f(&child(prefix, "weight"), &self.shape(), &self.weight);
        f(&child(prefix, "bias"), &[self.c_out], &self.bias);
    }

    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut) {
        let shape = self.shape();
        f(&child(prefix, "weight"), &shape, &mut self.weight);
        f(&child(prefix, "bias"), &[self.c_out], &mut self.bias);
    }
}
