//! The full track: every pixel input, its three outputs radiance itself (the baseline and
//! PRT-inspired designs).

use super::{KindSpec, Weight, ALL_INPUTS};

pub const SPEC: KindSpec = KindSpec {
    name: "full",
    inputs: ALL_INPUTS,
    terms: &[Weight::One],
};
