//! The albedo-factorised track: every pixel input, six outputs, kd·exp(first three) +
//! ks·exp(last three).

use super::{KindSpec, Weight, ALL_INPUTS};
use crate::encoding::features::feature;

pub const SPEC: KindSpec = KindSpec {
    name: "albedo",
    inputs: ALL_INPUTS,
    terms: &[
        Weight::Albedo(feature::KD.start),
        Weight::Albedo(feature::KS.start),
    ],
};
