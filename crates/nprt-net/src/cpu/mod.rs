//! The CPU engine: the transport networks' training step written for the host (fused bias and
//! activation passes, vectorised sin/cos, blocked matrix products) instead of through burn's
//! autodiff graph, which on SIREN designs lost to PyTorch. The light encoder stays on burn: the
//! gradient this engine finds at the light codes is handed back to burn's autodiff for it.
//!
//! Used wherever the network lives on burn's CPU backend in f32; any other device or precision
//! (the f64 gradient checks, a GPU) takes burn's own path, and a test holds the two together.

mod dense;
mod matmul;
mod peak;
pub mod sincos;
mod transport;

use burn::module::Param;
use burn::optim::GradientsParams;
use burn::tensor::{DType, Device, Tensor, TensorData};

use crate::batch::Batch;
use crate::design::NprtNet;
use crate::encoder::CODE_SIZE;
use crate::loss::Loss;
use crate::mlp::Mlp;
pub use dense::DenseStack;
pub use peak::{measured_peak, Peak};
pub use transport::{HostTransport, TransferCodes, TransportGradients};

/// Whether the CPU engine can run `net` on `device`.
pub fn applies(net: &NprtNet, device: &Device) -> bool {
    let weight = &net.tracks[0].shading.layers[0].weight;
    crate::compute::is_cpu(device) && weight.val().dtype() == DType::F32
}

/// The batch's loss and every parameter's gradient, with the transport networks on the CPU
/// engine and the encoder through burn's autodiff (`device` is an autodiff device).
pub fn gradients(
    net: &NprtNet,
    batch: &Batch,
    device: &Device,
    loss: Loss,
) -> (f64, GradientsParams) {
    let codes = net.encoder.forward(batch.light_tensor(device));
    let host_codes = host_values(codes.clone().into_data());
    let g = HostTransport::from_net(net).gradients(batch, &host_codes, loss);
    // d loss / d encoder = d (Σ codes ⊙ g.codes) / d encoder, with g.codes held constant.
    let views = host_codes.len() / CODE_SIZE;
    let d_codes = Tensor::<2>::from_data(TensorData::new(g.codes, [views, CODE_SIZE]), device);
    let surrogate = (codes * d_codes.detach()).sum();
    let mut params = GradientsParams::from_grads(surrogate.backward(), net);
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
    (g.loss, params)
}

/// Files the gradients `g` of `mlp`'s layers under their parameters' ids.
fn register(params: &mut GradientsParams, mlp: &Mlp, g: DenseStack, device: &Device) {
    for (layer, g) in mlp.layers.iter().zip(g.layers) {
        let weight = TensorData::new(g.weight, [g.d_in, g.d_out]);
        params.register::<2>(layer.weight.id, Tensor::from_data(weight, device));
        if let Some(Param { id, .. }) = &layer.bias {
            let bias = TensorData::new(g.bias, [g.d_out]);
            params.register::<1>(*id, Tensor::from_data(bias, device));
        }
    }
}

/// A tensor's values as f32 on the host.
pub fn host_values(data: TensorData) -> Vec<f32> {
    data.convert::<f32>()
        .try_into_vec::<f32>()
        .expect("converted to f32")
}
