//! The paper's albedo-factorised design: as PRT, but Φ outputs L^D and L^S and
//! L = kd·L^D + ks·L^S.

use super::{DesignSpec, Layout, LightPlan};
use crate::network::activation::Activation;
use crate::network::track_kind::TrackKind;

pub const SPEC: DesignSpec = DesignSpec {
    name: "albedo",
    tracks: &[TrackKind::Albedo],
    layout: Layout::Transfer { width: 256 },
    default_activation: Activation::Siren,
    paper_params: 187_718,
    cosine_rate: 5e-4,
    light: LightPlan::Encoder,
};
