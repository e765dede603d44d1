//! The paper's diffuse/specular design (D/S): two tracks of width 172, diffuse
//! F_T^D(x, n, kd) and specular F_T^S(x, n, ks, ωo, ωr, α), each with its own Φ;
//! L = kd·Φ^D + ks·Φ^S.

use super::{DesignSpec, Layout, LightPlan};
use crate::network::activation::Activation;
use crate::network::track_kind::TrackKind;

pub const SPEC: DesignSpec = DesignSpec {
    name: "dsep",
    tracks: &[TrackKind::Diffuse, TrackKind::Specular],
    layout: Layout::Transfer { width: 172 },
    default_activation: Activation::Siren,
    paper_params: 194_226,
    cosine_rate: 5e-4,
    light: LightPlan::Encoder,
};
