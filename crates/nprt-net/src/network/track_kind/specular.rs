//! D/S's specular track: position, normal, ks, ωo, ωr and α; its radiance weighted by ks.

use super::{KindSpec, Weight};
use crate::encoding::features::feature;

pub const SPEC: KindSpec = KindSpec {
    name: "specular",
    inputs: &[
        feature::POSITION,
        feature::NORMAL,
        feature::KS,
        feature::VIEW,
        feature::MIRROR,
        feature::ALPHA,
    ],
    terms: &[Weight::Albedo(feature::KS.start)],
};
