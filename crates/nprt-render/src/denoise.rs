//! Whether a traced model's direct light is denoised with Open Image Denoise: the one choice
//! `nprt render`, `nprt view`, `nprt bake` and Python take. By default (auto) as the recommended
//! recipe says: OIDN where it is installed, unless a check of the model on held-out views
//! (`nprt bake`'s, kept in the model folder as [`DenoiseCheck`]) measured its light better raw:
//! OIDN halves the error of builtin:room's 16 traced samples and adds a third to the KITCHEN's,
//! whose sun patches it blurs (docs/model.md, "The recommended recipe").

use std::path::Path;

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

use crate::oidn::Oidn;
use crate::relight::Relighter;
use nprt_net::model::folder::weights_hash;

/// auto (OIDN where it is installed, unless the model's check says raw), on (OIDN, or an error
/// saying how to install it) or off.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Denoise {
    Auto,
    On,
    Off,
}

impl Default for Denoise {
    /// The recommended recipe's: its traced light denoised where that measured better.
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

    /// The denoiser frames of `model` (loaded from folder `dir`) take: none for a model that
    /// learns all its light (an error where it was asked for by name).
    pub fn denoiser(self, model: &Relighter, dir: &Path) -> Result<Option<&'static Oidn>> {
        match (self, model.traces_direct()) {
            (Denoise::Off, _) | (Denoise::Auto, false) => Ok(None),
            (Denoise::On, false) => bail!(
                "--denoise-direct on: model '{}' does not trace direct light (train it with \
                 --direct traced)",
                dir.display()
            ),
            (Denoise::On, true) => Oidn::open()
                .map(Some)
                .context("--denoise-direct on needs Open Image Denoise (scripts/oidn.sh)"),
            (Denoise::Auto, true) => match DenoiseCheck::read(dir) {
                Some(check) if !check.denoise => Ok(None),
                _ => Ok(Oidn::open().ok()),
            },
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

/// What a check of a traced model on held-out views measured of its direct light raw and
/// denoised (L1, RMSE, dSSIM of its frames against path-traced references), kept in its folder
/// as `direct-check.json` for the weights it was measured on: [`Denoise::Auto`] denoises only
/// where that measured better. Training the folder further leaves it behind (its weights no
/// longer match).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DenoiseCheck {
    /// BLAKE3 of the weights file measured.
    pub weights: String,
    /// Whether denoised measured better: lower in at least two of the three errors.
    pub denoise: bool,
    pub views: usize,
    pub raw: [f64; 3],
    pub denoised: [f64; 3],
}

/// The file a model folder keeps its check in.
pub const DENOISE_CHECK_FILE: &str = "direct-check.json";

impl DenoiseCheck {
    /// The check of the model in `dir` from `views` held-out views' errors (L1, RMSE, dSSIM)
    /// raw and denoised.
    pub fn measured(dir: &Path, views: usize, raw: [f64; 3], denoised: [f64; 3]) -> Result<Self> {
        let wins = (raw.iter().zip(&denoised)).filter(|(r, d)| d < r).count();
        Ok(DenoiseCheck {
            weights: weights_hash(dir)?,
            denoise: wins >= 2,
            views,
            raw,
            denoised,
        })
    }

    /// The check kept in `dir`, where it is one of the weights there now.
    pub fn read(dir: &Path) -> Option<DenoiseCheck> {
        let bytes = nprt_io::read_input(&dir.join(DENOISE_CHECK_FILE)).ok()?;
        let check: DenoiseCheck = serde_json::from_slice(&bytes).ok()?;
        (weights_hash(dir).ok()? == check.weights).then_some(check)
    }

    pub fn write(&self, dir: &Path) -> Result<()> {
        nprt_io::write_file(
            &dir.join(DENOISE_CHECK_FILE),
            serde_json::to_vec_pretty(self)?,
        )
    }
}
