//! The arithmetic the frame path's networks run in: f32, as trained, or f16 weights and
//! activations with f32 sums, on tensor cores where the adapter has them (GPU kernels only).

use std::fmt;
use std::str::FromStr;

use anyhow::bail;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Precision {
    #[default]
    F32,
    F16,
}

impl FromStr for Precision {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> anyhow::Result<Self> {
        match s {
            "f32" => Ok(Precision::F32),
            "f16" => Ok(Precision::F16),
            _ => bail!("unknown precision '{s}': f32 or f16"),
        }
    }
}

impl fmt::Display for Precision {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(match self {
            Precision::F32 => "f32",
            Precision::F16 => "f16",
        })
    }
}
