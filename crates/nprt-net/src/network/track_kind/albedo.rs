//! The albedo-factorised track: every pixel input, six outputs, kd·exp(first three) +
//! ks·exp(last three).

use super::{KindSpec, Weight};
use crate::encoding::features::{feature, FEATURES};

pub const SPEC: KindSpec = KindSpec {
    name: "albedo",
    inputs: &[0..FEATURES],
    terms: &[
        Weight::Albedo(feature::KD.start),
        Weight::Albedo(feature::KS.start),
    ],
};
