//! The numbers the kernels take for the network's choices (activation, loss), as their
//! parameter blocks document them; a track kind's is `TrackKind::code`.

use crate::layers::activation::Activation;
use crate::loss::Loss;

/// A hidden layer's activation in `gemm`: 1 ReLU, 2 SIREN (0 is the linear last layer).
pub fn activation_code(a: Activation) -> u32 {
    match a {
        Activation::Relu => 1,
        Activation::Siren => 2,
    }
}

/// The loss in `radiance_loss`.
pub fn loss_code(loss: Loss) -> u32 {
    match loss {
        Loss::LogL1 => 0,
        Loss::RelL2 => 1,
    }
}

/// Added to an activation's code, `gemm`'s epilogue multiplies by its derivative at z instead.
pub const BACKWARD: u32 = 2;
