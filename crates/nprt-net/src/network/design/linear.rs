//! Beyond the paper: D/S made linear in the lighting. Its tracks are D/S's (diffuse
//! F_T^D(x, n, kd) and specular F_T^S(x, n, ks, ωo, ωr, α), SIREN, width 172), but each Φ reads
//! ŝ alone and outputs a transfer matrix T(x, ωo) of K coefficients per colour channel; the map
//! enters only as its projection e = P·E on a basis of K functions (`LightBasis`), and
//! L = kd·(T^D·e) + ks·(T^S·e). Exact under any gain or mixture of maps, as light transport is.

use super::{DesignSpec, Enters, Layout, LightPlan};
use crate::network::activation::Activation;
use crate::network::track_kind::TrackKind;

pub const SPEC: DesignSpec = DesignSpec {
    name: "linear",
    tracks: &[TrackKind::Diffuse, TrackKind::Specular],
    layout: Layout::Transfer { width: 172 },
    default_activation: Activation::Siren,
    paper_params: 0,
    cosine_rate: 5e-4,
    light: LightPlan::Basis(&[Enters::Combine, Enters::Combine]),
};
