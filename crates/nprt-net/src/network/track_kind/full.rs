//! The full track: every pixel input, its three outputs radiance itself (the baseline and
//! PRT-inspired designs).

use super::{KindSpec, Weight};
use crate::encoding::features::FEATURES;

pub const SPEC: KindSpec = KindSpec {
    name: "full",
    inputs: &[0..FEATURES],
    terms: &[Weight::One],
};
