//! The CPU engine: a design's training step written for the host (fused bias and activation
//! passes, vectorised sin/cos, blocked matrix products, the encoder's convolutions as matrix
//! products) instead of through burn's autodiff graph, which on SIREN designs lost to PyTorch
//! and spent a third of a step in the encoder's convolutions. burn keeps the weights and Adam.
//!
//! Used wherever the network is f32 and the engine is the CPU; the f64 gradient checks take
//! burn's own path, and a test holds the two together.

mod dense;
mod light_encoder;
mod matmul;
mod peak;
mod samples;
pub mod sincos;
mod transport;

use burn::module::Param;
use burn::nn::Linear;
use burn::optim::GradientsParams;
use burn::tensor::{DType, Device, Tensor, TensorData};

use crate::loss::Loss;
use crate::network::encoder::LightEncoder;
use crate::network::mlp::Mlp;
use crate::network::nprt_net::NprtNet;
pub use dense::{Dense, DenseStack};
pub use light_encoder::{EncoderPass, HostEncoder};
pub use peak::{measured_peak, Peak};
pub use samples::Samples;
pub use transport::{HostTransport, TransferCodes, TransportGradients};

/// Whether the CPU engine can run `net`: it computes in f32 (the f64 gradient checks take
/// burn's graph).
pub fn applies(net: &NprtNet) -> bool {
    net.tracks[0].shading.layers[0].weight.val().dtype() == DType::F32
}

/// The batch's loss and every parameter's gradient, computed on the CPU engine (`device` is
/// the autodiff device the network lives on).
pub fn gradients(
    net: &NprtNet,
    batch: &Samples,
    device: &Device,
    loss: Loss,
) -> (f64, GradientsParams) {
    let encoder = HostEncoder::from_burn(&net.encoder);
    let light = encoder.forward(batch.lights, batch.light_width);
    let (loss, mut params, d_codes) = transport_gradients(net, batch, &light.codes, device, loss);
    let grads = encoder.backward(&light, &d_codes);
    register_encoder(&mut params, &net.encoder, grads, &device.clone().inner());
    (loss, params)
}

/// Files the gradients `g` of `encoder`'s weights (from [`HostEncoder::backward`]) under their
/// parameters' ids.
pub fn register_encoder(
    params: &mut GradientsParams,
    encoder: &LightEncoder,
    g: HostEncoder,
    device: &Device,
) {
    for (conv, g) in encoder.convs.iter().zip(g.convs) {
        let shape = conv.weight.val().dims();
        let weight = Tensor::<4>::from_data(TensorData::new(g.weight, shape), device);
        params.register::<4>(conv.weight.id, weight);
        if let Some(Param { id, .. }) = &conv.bias {
            let bias = TensorData::new(g.bias, [shape[0]]);
            params.register::<1>(*id, Tensor::from_data(bias, device));
        }
    }
    register_linear(params, &encoder.to_code, g.to_code, device);
}

/// The part of [`gradients`] after the encoder: for the light `codes` (`views × CODE_SIZE`),
/// the batch's loss, the transport networks' gradients and the gradient at the codes.
pub fn transport_gradients(
    net: &NprtNet,
    batch: &Samples,
    codes: &[f32],
    device: &Device,
    loss: Loss,
) -> (f64, GradientsParams, Vec<f32>) {
    let g = HostTransport::from_net(net).gradients(batch, codes, loss);
    let mut params = GradientsParams::new();
    let inner = device.clone().inner();
    for (track, grads) in net.tracks.iter().zip(g.tracks) {
        if let (Some(grid), Some(g)) = (&track.grid, grads.grid) {
            let shape = grid.table.val().dims();
            let g = Tensor::<2>::from_data(TensorData::new(g, shape), &inner);
            params.register::<2>(grid.table.id, g);
        }
        if let (Some(mlp), Some(g)) = (&track.transfer, grads.transfer) {
            register(&mut params, mlp, g, &inner);
        }
        register(&mut params, &track.shading, grads.shading, &inner);
    }
    (g.loss, params, g.codes)
}

/// Files the gradients `g` of `mlp`'s layers under their parameters' ids.
fn register(params: &mut GradientsParams, mlp: &Mlp, g: DenseStack, device: &Device) {
    for (layer, g) in mlp.layers.iter().zip(g.layers) {
        register_linear(params, layer, g, device);
    }
}

/// Files the gradient `g` of one dense layer under its parameters' ids.
fn register_linear(params: &mut GradientsParams, layer: &Linear, g: Dense, device: &Device) {
    let weight = TensorData::new(g.weight, [g.d_in, g.d_out]);
    params.register::<2>(layer.weight.id, Tensor::from_data(weight, device));
    if let Some(Param { id, .. }) = &layer.bias {
        let bias = TensorData::new(g.bias, [g.d_out]);
        params.register::<1>(*id, Tensor::from_data(bias, device));
    }
}

/// `acc += x`, element by element: gradients summed over blocks, runs and maps.
fn accumulate(acc: &mut [f32], x: &[f32]) {
    acc.iter_mut().zip(x).for_each(|(a, v)| *a += v);
}
