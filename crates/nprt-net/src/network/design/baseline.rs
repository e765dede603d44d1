//! The paper's baseline: one ReLU MLP on [ê, inputs], 83 → 256 ×4 → 3.

use super::{DesignSpec, Layout, LightPlan};
use crate::network::activation::Activation;
use crate::network::track_kind::TrackKind;

pub const SPEC: DesignSpec = DesignSpec {
    name: "baseline",
    tracks: &[TrackKind::Full],
    layout: Layout::Direct {
        hidden: &[256, 256, 256, 256],
    },
    default_activation: Activation::Relu,
    paper_params: 219_651,
    // Its deep ReLU stack collapses to a constant at 1e-3.
    cosine_rate: 3e-4,
    light: LightPlan::Encoder,
};
