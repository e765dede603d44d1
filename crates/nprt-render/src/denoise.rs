//! Whether a traced model's direct light is denoised with Open Image Denoise: the one choice
//! `nprt render`, `nprt view`, `nprt bake` and Python take, by default as the recommended
//! recipe says (OIDN where it is installed).

use anyhow::{bail, Context, Result};

use crate::oidn::Oidn;
use crate::relight::Relighter;

/// auto (OIDN where it is installed), on (OIDN, or an error saying how to install it) or off.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Denoise {
    Auto,
    On,
    Off,
}

impl Default for Denoise {
    /// The recommended recipe's: its traced light denoised where OIDN is installed.
    fn default() -> Self {
        match nprt_net::RECIPE.denoise_direct {
            true => Denoise::Auto,
            false => Denoise::Off,
        }
    }
}

impl Denoise {
    pub const ALL: [Denoise; 3] = [Denoise::Auto, Denoise::On, Denoise::Off];

    pub fn name(self) -> &'static str {
        match self {
            Denoise::Auto => "auto",
            Denoise::On => "on",
            Denoise::Off => "off",
        }
    }

    /// The denoiser frames of `model` (from folder `what`) take: none for a model that learns
    /// all its light (an error where it was asked for by name).
    pub fn denoiser(self, model: &Relighter, what: &str) -> Result<Option<&'static Oidn>> {
        match (self, model.traces_direct()) {
            (Denoise::Off, _) | (Denoise::Auto, false) => Ok(None),
            (Denoise::On, false) => bail!(
                "--denoise-direct on: model '{what}' does not trace direct light (train it with \
                 --direct traced)"
            ),
            (Denoise::On, true) => Oidn::open()
                .map(Some)
                .context("--denoise-direct on needs Open Image Denoise (scripts/oidn.sh)"),
            (Denoise::Auto, true) => Ok(Oidn::open().ok()),
        }
    }
}

impl std::fmt::Display for Denoise {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Denoise {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Denoise::ALL
            .into_iter()
            .find(|d| d.name() == s)
            .ok_or_else(|| format!("unknown denoising '{s}': choose auto, on or off"))
    }
}
