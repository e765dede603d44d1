//! Helpers shared by the network tests: the variants every test covers, parameter shapes and
//! gradients as plain values.

use burn::module::{Module, ModuleMapper, ModuleVisitor, Param, ParamId};
use burn::optim::GradientsParams;
use burn::tensor::{DType, Tensor, TensorData};
use nprt_net::encoding::hash_grid::{LEVELS, LEVEL_FEATURES, TABLE_SIZE};
use nprt_net::{Activation, Batch, Design, Device, Init, Loss, ModelConfig, NprtNet};
use nprt_net::{PositionEncoding, FEATURES};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Ids and shapes of every parameter tensor.
pub struct Shapes(pub Vec<(ParamId, Vec<usize>)>);
impl ModuleVisitor for Shapes {
    fn visit_float<const D: usize>(&mut self, p: &Param<Tensor<D>>) {
        self.0.push((p.id, p.val().dims().to_vec()));
    }
}

/// Every design with the paper's inputs and each of its activations, then with a hash grid and
/// its own activation.
pub fn variants() -> Vec<ModelConfig> {
    let mut all = Vec::new();
    for design in Design::ALL {
        for activation in [Activation::Siren, Activation::Relu] {
            all.push(ModelConfig::new(design, Some(activation)));
        }
        all.push(ModelConfig {
            encoding: PositionEncoding::HashGrid,
            ..ModelConfig::new(design, None)
        });
    }
    all
}

/// Gives every hash grid table values of order one, so that the encoding weighs in the output
/// as in a trained network (an untrained grid holds ±1e-4, next to nothing).
pub struct LoudGrids(Pcg64Mcg);
impl ModuleMapper for LoudGrids {
    fn map_float<const D: usize>(&mut self, p: Param<Tensor<D>>) -> Param<Tensor<D>> {
        if p.val().dims()[..] != [LEVELS * TABLE_SIZE, LEVEL_FEATURES] {
            return p;
        }
        p.map(|t| {
            let values: Vec<f32> = (0..LEVELS * TABLE_SIZE * LEVEL_FEATURES)
                .map(|_| self.0.random::<f32>() * 2.0 - 1.0)
                .collect();
            let data = TensorData::new(values, t.dims());
            let loud = Tensor::from_data(data, (&t.device(), t.dtype()));
            if t.is_autodiff() {
                loud.require_grad()
            } else {
                loud
            }
        })
    }
}

pub fn loud_grids(net: NprtNet) -> NprtNet {
    net.map(&mut LoudGrids(Pcg64Mcg::seed_from_u64(17)))
}

/// A batch of `n` samples that is not a whole number of the CPU engine's blocks, with `views`
/// maps of 64×32 and samples of each map spread through it; seeded.
pub fn random_batch(n: usize, views: usize, seed: u64) -> Batch {
    let w = 64;
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut r = |lo: f32, hi: f32, k: usize| -> Vec<f32> {
        (0..k)
            .map(|_| lo + (hi - lo) * rng.random::<f32>())
            .collect()
    };
    Batch {
        features: r(0.0, 1.0, n * FEATURES),
        radiance: r(0.0, 3.0, n * 3),
        view: (0..n as i64)
            .map(|i| (i * 7 + i / 5) % views as i64)
            .collect(),
        scale: r(0.5, 1.5, n * 3),
        lights: r(0.0, 2.0, views * 3 * w * w / 2),
        light_width: w,
        picks: None,
    }
}

/// burn's loss and gradients in f64 on the CPU, for `config` built from seed 4 with loud
/// grids: the truth that f32 paths are measured against.
pub fn exact_gradients(
    config: &ModelConfig,
    batch: &Batch,
    objective: Loss,
) -> (f64, GradientsParams) {
    let device = Device::flex().autodiff();
    let mut init = Init::with_dtype(4, &device, DType::F64);
    let net = loud_grids(config.build(&mut init));
    assert!(!nprt_net::cpu::applies(&net));
    let (n, w) = (batch.len(), batch.light_width);
    let views = batch.lights.len() / (3 * w * w / 2);
    let pred = net.forward(
        init.tensor(batch.features.clone(), [n, FEATURES]),
        init.tensor(batch.lights.clone(), [views, 3, w / 2, w]),
        Tensor::from_data(TensorData::new(batch.view.clone(), [n]), &device),
        init.tensor(batch.scale.clone(), [n, 3]),
    );
    let loss = objective.mean(pred, init.tensor(batch.radiance.clone(), [n, 3]));
    let value = loss.clone().into_scalar::<f64>();
    (value, GradientsParams::from_grads(loss.backward(), &net))
}

/// How far several gradients of one parameter are from the truth.
pub struct GradientError<const K: usize> {
    pub id: ParamId,
    pub dims: Vec<usize>,
    /// Euclidean distance of each candidate from the truth.
    pub errors: [f64; K],
    /// The truth's Euclidean norm.
    pub norm: f64,
}

/// For every parameter of `net` (a network or a part of one), the distance of each of
/// `candidates` from `truth`.
pub fn gradient_errors<M: Module, const K: usize>(
    net: &M,
    truth: &GradientsParams,
    candidates: [&GradientsParams; K],
) -> Vec<GradientError<K>> {
    let mut shapes = Shapes(Vec::new());
    net.visit(&mut shapes);
    shapes
        .0
        .into_iter()
        .map(|(id, dims)| {
            let exact = gradient_values(truth, id, dims.len());
            let errors = candidates.map(|g| {
                gradient_values(g, id, dims.len())
                    .iter()
                    .zip(&exact)
                    .map(|(x, y)| (x - y).powi(2))
                    .sum::<f64>()
                    .sqrt()
            });
            let norm = exact.iter().map(|v| v * v).sum::<f64>().sqrt();
            GradientError {
                id,
                dims,
                errors,
                norm,
            }
        })
        .collect()
}

/// Every parameter's gradient as f64 values.
pub fn gradient_values(grads: &GradientsParams, id: ParamId, rank: usize) -> Vec<f64> {
    match rank {
        1 => grads.get::<1>(id).map(|g| g.into_data()),
        2 => grads.get::<2>(id).map(|g| g.into_data()),
        4 => grads.get::<4>(id).map(|g| g.into_data()),
        _ => unreachable!(),
    }
    .expect("every parameter has a gradient")
    .convert::<f64>()
    .try_into_vec::<f64>()
    .unwrap()
}
