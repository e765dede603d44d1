//! The numbers the kernels take for the network's choices (activation, track kind, loss), as
//! their parameter blocks document them.

use crate::network::activation::Activation;
use crate::network::track::TrackKind;
use crate::training::loss::Loss;

/// A hidden layer's activation in `gemm`: 1 ReLU, 2 SIREN (0 is the linear last layer).
pub fn activation_code(a: Activation) -> u32 {
    match a {
        Activation::Relu => 1,
        Activation::Siren => 2,
    }
}

/// A track's kind in `combine` and `radiance_loss`.
pub fn kind_code(kind: TrackKind) -> u32 {
    match kind {
        TrackKind::Full => 0,
        TrackKind::Albedo => 1,
        TrackKind::Diffuse => 2,
        TrackKind::Specular => 3,
    }
}

/// The loss in `radiance_loss`.
pub fn loss_code(loss: Loss) -> u32 {
    match loss {
        Loss::LogL1 => 0,
        Loss::RelL2 => 1,
    }
}
