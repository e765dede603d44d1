//! The four transport designs of the paper (its Table 1): their names, sizes and activations.

use crate::choice::named_choice;
use crate::network::activation::Activation;

/// Size of the transport code ŝ.
pub const TRANSPORT_CODE: usize = 64;

/// The transport design (the paper's Table 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Design {
    /// One MLP on [ê, inputs]: 83 → 256 ×4 → 3.
    Baseline,
    /// PRT-inspired: F_T(inputs) = ŝ, then Φ(ŝ, ê) → radiance.
    Prt,
    /// As PRT, but Φ outputs L^D and L^S and L = kd·L^D + ks·L^S.
    Albedo,
    /// Two tracks of width 172: diffuse F_T^D(x, n, kd) and specular F_T^S(x, n, ks, ωo, ωr, α),
    /// each with its own Φ; L = kd·Φ^D + ks·Φ^S.
    Dsep,
}

named_choice!(Design, "design", {
    Baseline => "baseline",
    Prt => "prt",
    Albedo => "albedo",
    Dsep => "dsep",
});

impl Design {
    /// Transport parameter count the paper gives (Table 1).
    pub fn paper_params(self) -> usize {
        match self {
            Design::Baseline => 219_651,
            Design::Prt => 186_947,
            Design::Albedo => 187_718,
            Design::Dsep => 194_226,
        }
    }

    /// The paper's activation for the layers that see the pixel inputs: ReLU for the baseline,
    /// SIREN for the transport networks F_T of the other designs.
    pub fn default_activation(self) -> Activation {
        match self {
            Design::Baseline => Activation::Relu,
            _ => Activation::Siren,
        }
    }
}
