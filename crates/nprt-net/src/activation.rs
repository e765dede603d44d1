//! The two hidden-layer activations of the paper.

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
