//! Seeded parameter initialisation, and the dense and convolution layers built with it.

use burn::module::{Param, ParamId};
use burn::nn::conv::Conv2d;
use burn::nn::{Linear, PaddingConfig2d};
use burn::tensor::{DType, Device, Tensor, TensorData};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Seeded source of initial parameters.
///
/// Values come from our own PCG stream, not burn's global RNG, so one seed gives one model on
/// any device. Parameter ids are numbered in construction order: a model rebuilt from its config
/// has the same ids, which is what keys the optimiser state of a resumed run.
pub struct Init {
    rng: Pcg64Mcg,
    next_id: u64,
    pub device: Device,
    dtype: DType,
}

impl Init {
    pub fn new(seed: u64, device: &Device) -> Self {
        Self::with_dtype(seed, device, DType::F32)
    }

    /// As `new`, with parameters stored in `dtype` (f64 for finite-difference checks).
    pub fn with_dtype(seed: u64, device: &Device, dtype: DType) -> Self {
        Init {
            rng: Pcg64Mcg::seed_from_u64(seed ^ 0x6e70_7274_5f69_6e69),
            next_id: 1,
            device: device.clone(),
            dtype,
        }
    }

    /// A parameter of the given shape drawn uniformly from [−bound, bound].
    pub fn uniform<const D: usize>(&mut self, shape: [usize; D], bound: f32) -> Param<Tensor<D>> {
        let n = shape.iter().product();
        let values: Vec<f32> = (0..n)
            .map(|_| (self.rng.random::<f32>() * 2.0 - 1.0) * bound)
            .collect();
        let data = TensorData::new(values, shape);
        let id = ParamId::from(self.next_id);
        self.next_id += 1;
        let tensor = Tensor::from_data(data, (&self.device, self.dtype));
        let tensor = if self.device.is_autodiff() {
            tensor.require_grad()
        } else {
            tensor
        };
        Param::initialized(id, tensor)
    }

    /// A constant input tensor in this initialiser's precision.
    pub fn tensor<const D: usize>(&self, values: Vec<f32>, shape: [usize; D]) -> Tensor<D> {
        Tensor::from_data(TensorData::new(values, shape), (&self.device, self.dtype))
    }
}

/// One dense layer `y = xW + b` with the bound for W chosen by the caller; the bias takes
/// PyTorch's default bound 1/√fan_in, as Sitzmann et al.'s reference code keeps it.
pub(crate) fn dense(init: &mut Init, d_in: usize, d_out: usize, weight_bound: f32) -> Linear {
    let bias_bound = 1.0 / (d_in as f32).sqrt();
    Linear {
        weight: init.uniform([d_in, d_out], weight_bound),
        bias: Some(init.uniform([d_out], bias_bound)),
    }
}

/// A k×k convolution with "same" padding and PyTorch's default initialisation
/// (U(±1/√fan_in) for weight and bias).
pub fn conv2d(init: &mut Init, c_in: usize, c_out: usize, k: usize) -> Conv2d {
    let bound = 1.0 / ((c_in * k * k) as f32).sqrt();
    Conv2d {
        weight: init.uniform([c_out, c_in, k, k], bound),
        bias: Some(init.uniform([c_out], bound)),
        stride: [1, 1],
        kernel_size: [k, k],
        dilation: [1, 1],
        groups: 1,
        padding: PaddingConfig2d::Same,
    }
}

/// `bias` plus `shift`, as a fresh leaf: under autodiff it trains as any parameter (a bias
/// computed from the old one would not be a leaf, which burn refuses to train); elsewhere it is
/// a plain tensor, which cannot require a gradient.
pub fn shifted_bias(bias: Option<Param<Tensor<1>>>, shift: f32) -> Option<Param<Tensor<1>>> {
    bias.map(|b| {
        b.map(|t| {
            let t = t.add_scalar(shift).detach();
            if t.is_autodiff() {
                t.require_grad()
            } else {
                t
            }
        })
    })
}
