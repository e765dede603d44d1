//! The linear design's light code: the map's projection e = P·E onto a basis of K functions on
//! the sphere, per colour channel, with nothing between the map and the code that is not
//! linear (no log, no bias, no ReLU). Radiance is then a dot product with the code, so a model
//! answers a·E₁ + b·E₂ with a·(its answer under E₁) + b·(its answer under E₂), to rounding.
//!
//! P is fixed (real spherical harmonics up to a band) or learned with the network. Its rows are
//! stored as function values at the map's texels; the texels' solid angles are applied when it
//! projects, so Adam's steps, which are about the same size for every value, move the functions
//! and not the quadrature.

use std::fmt;
use std::str::FromStr;

use glam::Vec2;
use nprt_scene::envmap::uv_to_direction;
use serde::{Deserialize, Serialize};

use crate::encoding::spherical_harmonics::{basis, MAX_BANDS};
use crate::init::Init;
use crate::parameters::{child, Parameters, Visit, VisitMut};

/// The most functions a learned basis may have.
pub const MAX_LEARNED: usize = 1024;

/// Which basis the lighting is projected on: `sh:L` (real spherical harmonics of bands 0..=L,
/// (L+1)² functions) or `learned:K` (K functions trained with the network, started from the
/// spherical harmonics that fit and small random functions after them).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum BasisChoice {
    Sh { band: usize },
    Learned { size: usize },
}

impl Default for BasisChoice {
    /// Band 4, 25 functions: SH PRT 25's lighting.
    fn default() -> Self {
        BasisChoice::Sh { band: 4 }
    }
}

impl BasisChoice {
    /// K: the basis' functions.
    pub fn size(self) -> usize {
        match self {
            BasisChoice::Sh { band } => (band + 1) * (band + 1),
            BasisChoice::Learned { size } => size,
        }
    }

    pub fn is_learned(self) -> bool {
        matches!(self, BasisChoice::Learned { .. })
    }
}

impl fmt::Display for BasisChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BasisChoice::Sh { band } => write!(f, "sh:{band}"),
            BasisChoice::Learned { size } => write!(f, "learned:{size}"),
        }
    }
}

impl FromStr for BasisChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let usage = "a light basis is sh:L (spherical harmonics to band L, 0 to 15) or learned:K \
                     (K functions, 1 to 1024)";
        let (kind, n) = s.split_once(':').ok_or_else(|| format!("'{s}': {usage}"))?;
        let n: usize = n.parse().map_err(|_| format!("'{s}': {usage}"))?;
        match kind {
            "sh" if n < MAX_BANDS => Ok(BasisChoice::Sh { band: n }),
            "learned" if (1..=MAX_LEARNED).contains(&n) => Ok(BasisChoice::Learned { size: n }),
            _ => Err(format!("'{s}': {usage}")),
        }
    }
}

impl TryFrom<String> for BasisChoice {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        s.parse()
    }
}

impl From<BasisChoice> for String {
    fn from(b: BasisChoice) -> String {
        b.to_string()
    }
}

/// The projection P onto K functions of a W × W/2 lat-long map, or (same shapes) its
/// gradient. The CPU engine runs it (`cpu::light_basis`).
#[derive(Clone, Debug, PartialEq)]
pub struct LightBasis {
    pub choice: BasisChoice,
    /// W of the maps it projects.
    pub width: usize,
    /// K × (W/2 · W), row-major: each function's value at each texel's centre.
    pub functions: Vec<f32>,
}

impl LightBasis {
    pub fn new(init: &mut Init, choice: BasisChoice, width: usize) -> Self {
        let k = choice.size();
        let texels = width * width / 2;
        // As many whole SH bands as fit; a learned basis continues with small random functions.
        let bands = ((k as f64).sqrt().floor() as usize).min(MAX_BANDS);
        let mut functions = vec![0.0; k * texels];
        let mut y = vec![0.0; bands * bands];
        for t in 0..texels {
            basis(bands, texel_direction(t, width), &mut y);
            for (j, v) in y.iter().enumerate() {
                functions[j * texels + t] = *v;
            }
        }
        let rest = init.uniform((k - bands * bands) * texels, 0.1);
        functions[bands * bands * texels..].copy_from_slice(&rest);
        LightBasis {
            choice,
            width,
            functions,
        }
    }

    /// K: the functions, and the light code's size per colour channel.
    pub fn size(&self) -> usize {
        self.choice.size()
    }

    /// The solid angle of each texel of the W × W/2 map, row-major (exact for its row's band
    /// of latitude): what both engines and the export multiply the functions by.
    pub fn texel_solid_angles(&self) -> Vec<f32> {
        let (w, h) = (self.width, self.width / 2);
        let pi = std::f64::consts::PI;
        (0..w * h)
            .map(|t| {
                let r = t / w;
                let band =
                    (pi * r as f64 / h as f64).cos() - (pi * (r + 1) as f64 / h as f64).cos();
                (2.0 * pi / w as f64 * band) as f32
            })
            .collect()
    }
}

/// The world direction of texel `t` (row-major) of a W × W/2 lat-long map, at its centre.
fn texel_direction(t: usize, width: usize) -> glam::Vec3 {
    let (x, y) = (t % width, t / width);
    uv_to_direction(Vec2::new(
        (x as f32 + 0.5) / width as f32,
        (y as f32 + 0.5) / (width / 2) as f32,
    ))
}

/// Only a learned basis has parameters; spherical harmonics are rebuilt from the config.
impl Parameters for LightBasis {
    fn visit(&self, prefix: &str, f: &mut Visit) {
        if self.choice.is_learned() {
            let shape = [self.size(), self.width * self.width / 2];
            f(&child(prefix, "functions"), &shape, &self.functions);
        }
    }

    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut) {
        if self.choice.is_learned() {
            let shape = [self.size(), self.width * self.width / 2];
            f(&child(prefix, "functions"), &shape, &mut self.functions);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn choices_read_back_and_bad_ones_say_what_is_accepted() {
        for s in ["sh:0", "sh:2", "sh:8", "learned:64"] {
            let b: BasisChoice = s.parse().unwrap();
            assert_eq!(b.to_string(), s);
        }
        assert_eq!("sh:8".parse::<BasisChoice>().unwrap().size(), 81);
        for bad in [
            "sh",
            "sh:16",
            "learned:0",
            "learned:5000",
            "fourier:3",
            "sh:-1",
        ] {
            let e = bad.parse::<BasisChoice>().unwrap_err();
            assert!(e.contains("sh:L") && e.contains(bad), "{e}");
        }
    }

    #[test]
    fn a_learned_basis_starts_from_the_harmonics_that_fit() {
        let sh = LightBasis::new(&mut Init::new(1), BasisChoice::Sh { band: 2 }, 32);
        let learned = LightBasis::new(&mut Init::new(1), BasisChoice::Learned { size: 12 }, 32);
        let texels = 32 * 16;
        assert_eq!(learned.functions[..9 * texels], sh.functions[..]);
        assert!(learned.functions[9 * texels..].iter().any(|&v| v != 0.0));
        assert_eq!(sh.num_params(), 0);
        assert_eq!(learned.num_params(), 12 * texels);
    }
}
