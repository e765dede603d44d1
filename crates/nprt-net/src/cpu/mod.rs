//! The CPU engine: every network's training step and inference written for the host (fused
//! bias and activation passes, vectorised sin/cos, blocked matrix products, convolutions as
//! matrix products) on the weights `network/` defines, which it reads and whose gradients it
//! writes as networks of the same shapes. burn's autodiff graph, which it replaced, lost to
//! PyTorch on SIREN designs and spent a third of a step in the encoder's convolutions.
//!
//! Tests hold it to f64 finite differences of its own forward pass (tests/net.rs).

mod frame;
mod light_encoder;
mod light_model;
pub(crate) mod radiance_cache;
mod samples;
mod transport;
mod unet;

// The kernels these passes run, nprt-engine's.
use nprt_engine::cpu::{accumulate, dense, matmul, pool, relu};
pub use nprt_engine::cpu::{peak, sincos};

use crate::loss::Loss;
use crate::network::nprt_net::NprtNet;
pub use frame::{CpuShading, HostCode, HostRows};
pub use light_encoder::EncoderPass;
pub use light_model::LightPass;
pub use peak::{measured_peak, Peak};
pub use radiance_cache::HostCacheSteps;
pub use samples::Samples;
pub use transport::{KeptRows, TransportGradients};
pub use unet::UnetBatch;

/// The batch's mean `loss` and every parameter's gradient (a network of `net`'s shapes).
pub fn gradients(net: &NprtNet, batch: &Samples, loss: Loss) -> (f64, NprtNet) {
    let pass = net.light.forward(batch.lights, batch.light_width);
    let g = net.transport_gradients(batch, pass.codes(), loss);
    let light = net.light.backward(&pass, batch.lights, &g.codes);
    (
        g.loss,
        NprtNet {
            light,
            tracks: g.tracks,
        },
    )
}

/// The batch's predicted radiance (`n × 3`, its maps' scales applied).
pub fn predict(net: &NprtNet, batch: &Samples) -> Vec<f32> {
    let pass = net.light.forward(batch.lights, batch.light_width);
    net.predict(batch, pass.codes())
}
