//! Beyond the paper: the linear design without the transfer code ŝ. Its tracks are D/S's
//! (diffuse and specular inputs), each one SIREN MLP from the pixel inputs straight to the
//! transfer matrix T(x, ωo) of K coefficients per colour channel (four hidden layers of 172),
//! dotted with the map's projection e = P·E on the basis as in the linear design. Since the
//! light enters only at that dot product, a still camera keeps T and a lighting change is K
//! multiply-adds per term and channel, whichever network made T: the split into a transfer
//! network and a shading network buys a linear design nothing at run time. Its one file beyond
//! the design list is this one (docs/model.md counts them).

use super::{DesignSpec, Enters, Layout, LightPlan};
use crate::network::activation::Activation;
use crate::network::track_kind::TrackKind;

pub const SPEC: DesignSpec = DesignSpec {
    name: "linear-direct",
    tracks: &[TrackKind::Diffuse, TrackKind::Specular],
    layout: Layout::Direct {
        hidden: &[172, 172, 172, 172],
    },
    default_activation: Activation::Siren,
    paper_params: 0,
    // The linear design's rate, not measured for this one.
    cosine_rate: 5e-4,
    light: LightPlan::Basis(&[Enters::Combine, Enters::Combine]),
};
