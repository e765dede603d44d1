//! The two hidden-layer activations of the paper.

use crate::choice::named_choice;

/// SIREN's frequency factor ω0 (Sitzmann et al. 2020), as the paper uses.
pub const OMEGA_0: f32 = 30.0;

/// Hidden-layer non-linearity of a transport network.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Activation {
    /// sin(ω0·(Wx + b)) with Sitzmann et al.'s initialisation.
    Siren,
    /// max(0, Wx + b) with PyTorch's default initialisation.
    Relu,
}

named_choice!(Activation, "activation", {
    Siren => "siren",
    Relu => "relu",
});
