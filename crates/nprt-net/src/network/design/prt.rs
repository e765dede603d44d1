//! The paper's PRT-inspired design: F_T(inputs) = ŝ, then Φ(ŝ, ê) → radiance.

use super::{DesignSpec, Layout, LightPlan};
use crate::network::activation::Activation;
use crate::network::track_kind::TrackKind;

pub const SPEC: DesignSpec = DesignSpec {
    name: "prt",
    tracks: &[TrackKind::Full],
    layout: Layout::Transfer { width: 256 },
    default_activation: Activation::Siren,
    paper_params: 186_947,
    cosine_rate: 5e-4,
    light: LightPlan::Encoder,
};
