//! Beyond the paper: a design linear in the lighting for its diffuse light only. Its tracks are
//! D/S's (diffuse F_T^D(x, n, kd) and specular F_T^S(x, n, ks, ωo, ωr, α), SIREN, width 172)
//! on the map's projection e = P·E on a basis, as the linear design's; the diffuse track is
//! the linear design's (Φ^D(ŝ) a transfer matrix dotted with e: exact under any gain or mixture
//! of maps), the specular track's Φ^S reads e through its first layer as the paper's Φ reads ê
//! (non-linear in the lighting: it may reshape the projection, where a linear track can only
//! weight it). L = kd·(T^D·e) + ks·Φ^S(ŝ, e). A design that mixes the two entries of the light;
//! docs/model.md counts the files it took.

use super::{DesignSpec, Enters, Layout, LightPlan};
use crate::network::activation::Activation;
use crate::network::track_kind::TrackKind;

pub const SPEC: DesignSpec = DesignSpec {
    name: "linear-diffuse",
    tracks: &[TrackKind::Diffuse, TrackKind::Specular],
    layout: Layout::Transfer { width: 172 },
    default_activation: Activation::Siren,
    paper_params: 0,
    // The linear design's rate, not measured for this one.
    cosine_rate: 5e-4,
    light: LightPlan::Basis(&[Enters::Combine, Enters::FirstLayer]),
};
