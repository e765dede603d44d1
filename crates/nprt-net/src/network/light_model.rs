//! What turns an environment map into the light code the transport tracks read: the paper's
//! convolutional encoder, or the linear design's projection onto a basis.

use anyhow::{bail, Result};

use crate::network::encoder::{LightEncoder, Texels, CODE_SIZE};
use crate::network::light_basis::LightBasis;
use crate::parameters::{child, Parameters, Visit, VisitMut};

/// A network's light model, or (same shapes) its gradient.
#[derive(Clone, Debug, PartialEq)]
pub enum LightModel {
    /// The paper's CNN F_L on log(1 + map): a 64-d code the shading networks read.
    Encoder(LightEncoder),
    /// e = P·map per channel: K coefficients per channel that the tracks' transfer
    /// coefficients are dotted with.
    Basis(LightBasis),
}

impl LightModel {
    /// The light code's values per lighting.
    pub fn code_size(&self) -> usize {
        match self {
            LightModel::Encoder(_) => CODE_SIZE,
            LightModel::Basis(b) => 3 * b.size(),
        }
    }

    /// How the map's texels reach it: log(1 + x) for the encoder, as they are for a basis.
    pub fn texels(&self) -> Texels {
        match self {
            LightModel::Encoder(_) => Texels::Log,
            LightModel::Basis(_) => Texels::Linear,
        }
    }

    /// The convolutional encoder; a basis is refused, by name.
    pub fn encoder(&self) -> Result<&LightEncoder> {
        match self {
            LightModel::Encoder(e) => Ok(e),
            LightModel::Basis(b) => bail!(
                "the linear design (light basis {}) has no encoder: its light code is the map's \
                 projection on that basis",
                b.choice
            ),
        }
    }
}

/// The encoder's tensors are named `encoder.…` as the weights files have always named them; a
/// learned basis' `basis.functions`.
impl Parameters for LightModel {
    fn visit(&self, prefix: &str, f: &mut Visit) {
        match self {
            LightModel::Encoder(e) => e.visit(&child(prefix, "encoder"), f),
            LightModel::Basis(b) => b.visit(&child(prefix, "basis"), f),
        }
    }

    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut) {
        match self {
            LightModel::Encoder(e) => e.visit_mut(&child(prefix, "encoder"), f),
            LightModel::Basis(b) => b.visit_mut(&child(prefix, "basis"), f),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::init::Init;
    use crate::model::config::ModelConfig;
    use crate::network::design::Design;

    /// Where only an encoder will do, a basis is refused by name.
    #[test]
    fn a_basis_is_refused_where_only_the_encoder_runs() {
        let linear = ModelConfig::new(Design::Linear, None).build(&mut Init::new(0));
        let e = linear.encoder().unwrap_err().to_string();
        assert!(e.contains("sh:4") && e.contains("no encoder"), "{e}");
        let dsep = ModelConfig::new(Design::Dsep, None).build(&mut Init::new(0));
        assert!(dsep.encoder().is_ok());
        assert_eq!((linear.light.code_size(), dsep.light.code_size()), (75, 64));
    }
}
