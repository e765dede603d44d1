//! Dense layers, the two activations of the paper and their initialisations.

use burn::module::{Module, Param, ParamId};
use burn::nn::conv::Conv2d;
use burn::nn::{Linear, PaddingConfig2d};
use burn::tensor::activation::relu;
use burn::tensor::{DType, Device, Tensor, TensorData};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

/// SIREN's frequency factor ω0 (Sitzmann et al. 2020), as the paper uses.
pub const OMEGA_0: f32 = 30.0;

/// Hidden-layer non-linearity of a transport network.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Activation {
    /// sin(ω0·(Wx + b)) with Sitzmann et al.'s initialisation.
    Siren,
    /// max(0, Wx + b) with PyTorch's default initialisation.
    Relu,
}

impl Activation {
    pub fn name(self) -> &'static str {
        match self {
            Activation::Siren => "siren",
            Activation::Relu => "relu",
        }
    }
}

impl std::str::FromStr for Activation {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "siren" => Ok(Activation::Siren),
            "relu" => Ok(Activation::Relu),
            _ => Err(format!("unknown activation '{s}' (expected siren or relu)")),
        }
    }
}

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
fn dense(init: &mut Init, d_in: usize, d_out: usize, weight_bound: f32) -> Linear {
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
                let bound = match activation {
                    // PyTorch's kaiming_uniform(a=√5) for nn.Linear reduces to 1/√fan_in.
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
