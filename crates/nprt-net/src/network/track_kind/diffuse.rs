//! D/S's diffuse track: position, normal and kd; its radiance weighted by kd.

use super::{KindSpec, Weight};
use crate::encoding::features::feature;

pub const SPEC: KindSpec = KindSpec {
    name: "diffuse",
    inputs: &[feature::POSITION, feature::NORMAL, feature::KD],
    terms: &[Weight::Albedo(feature::KD.start)],
};
