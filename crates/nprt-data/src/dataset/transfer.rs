//! Transfer vectors (`nprt generate --transfer sh:L`): each training pixel's light transport
//! projected on the real spherical harmonics of bands 0..L, recorded by path tracing once for
//! every lighting, so that radiance under any map whose projection is c is Σ_k T_k ⊙ c_k. The
//! direct part (paths that escape after one surface vertex) is kept apart, as the radiance's
//! is, for designs that trace the direct light at run time. Stored in the view files as
//! `transfer.K.R/G/B` and `transfer_direct.K.R/G/B` (K = 0 … (L+1)² − 1).

use std::collections::HashMap;
use std::fmt;

use anyhow::{bail, Context, Result};
use nprt_scene::spherical_harmonics::{basis, MAX_BANDS};
use nprt_scene::Camera;
use nprt_trace::{render_transport, RenderSettings, TraceScene};
use serde::{Deserialize, Serialize};

/// The highest SH band `--transfer` records: (8 + 1)² = 81 coefficients per channel, twice
/// (whole and direct), 486 floats per pixel.
pub const MAX_TRANSFER_BAND: u32 = 8;

/// The basis transport is recorded on: the real SH up to band `band` (`sh:L`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct TransferBasis {
    pub band: u32,
}

impl TransferBasis {
    /// `sh:L`, or `none` (no vectors): what `nprt generate --transfer` and Python's
    /// `generate(transfer=…)` take.
    pub fn parse_choice(s: &str) -> Result<Option<TransferBasis>> {
        match s {
            "none" => Ok(None),
            _ => s.parse().map(Some).context("or none, for no vectors"),
        }
    }

    /// Coefficients per colour channel, (L + 1)².
    pub fn coefficients(self) -> usize {
        ((self.band + 1) * (self.band + 1)) as usize
    }

    /// Floats one pixel's transfer takes per part (whole or direct): 3 per coefficient.
    pub fn floats(self) -> usize {
        3 * self.coefficients()
    }

    /// Records `camera`'s per-pixel transfer at `settings` (BSDF-sampled paths, see
    /// [`render_transport`]).
    pub fn record(self, ts: &TraceScene, camera: &Camera, settings: &RenderSettings) -> Transfer {
        let k = self.coefficients();
        let bands = self.band as usize + 1;
        debug_assert!(bands <= MAX_BANDS);
        let per_pixel = render_transport(ts, camera, settings, 2 * k, &|d, depth, out| {
            basis(bands, d, &mut out[..k]);
            // The direct part: the same values for a path escaping after its first vertex.
            let (all, direct) = out.split_at_mut(k);
            match depth {
                1 => direct.copy_from_slice(all),
                _ => direct.fill(0.0),
            }
        });
        let mut t = Transfer {
            basis: self,
            all: Vec::with_capacity(per_pixel.len() * 3 * k),
            direct: Vec::with_capacity(per_pixel.len() * 3 * k),
        };
        for p in per_pixel {
            t.all.extend(p[..k].iter().flat_map(|v| v.to_array()));
            t.direct.extend(p[k..].iter().flat_map(|v| v.to_array()));
        }
        t
    }
}

impl fmt::Display for TransferBasis {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "sh:{}", self.band)
    }
}

impl std::str::FromStr for TransferBasis {
    type Err = anyhow::Error;

    fn from_str(s: &str) -> Result<Self> {
        let band = s
            .strip_prefix("sh:")
            .and_then(|b| b.parse::<u32>().ok())
            .with_context(|| {
                format!("transfer basis '{s}': expected sh:L, the SH bands 0..L (e.g. sh:2)")
            })?;
        if band > MAX_TRANSFER_BAND {
            bail!(
                "transfer basis '{s}': at most sh:{MAX_TRANSFER_BAND} ({} coefficients per channel)",
                (MAX_TRANSFER_BAND + 1).pow(2)
            );
        }
        Ok(TransferBasis { band })
    }
}

impl TryFrom<String> for TransferBasis {
    type Error = anyhow::Error;

    fn try_from(s: String) -> Result<Self> {
        s.parse()
    }
}

impl From<TransferBasis> for String {
    fn from(b: TransferBasis) -> String {
        b.to_string()
    }
}

/// One view's transfer: per pixel, per coefficient, R G B; the whole and its direct part.
#[derive(Clone, Debug, PartialEq)]
pub struct Transfer {
    pub basis: TransferBasis,
    pub all: Vec<f32>,
    pub direct: Vec<f32>,
}

/// The two parts' channel prefixes in a view file.
const PARTS: [&str; 2] = ["transfer", "transfer_direct"];
const RGB: [&str; 3] = ["R", "G", "B"];

/// The largest transfer value a view may hold: half of f16's largest (65,504), so that the
/// pack's f16 holds it and the difference of two (a pixel's indirect part) too. Real transfer
/// stays within tens (the basis functions' size times 4π); a value past f16's range was packed
/// as infinity and training blamed its learning rate.
pub const MAX_TRANSFER: f32 = 32_752.0;

impl Transfer {
    /// The view file's channels: one per part, coefficient and colour.
    pub fn channels(&self) -> Vec<(String, Vec<f32>)> {
        let k = self.basis.coefficients();
        let mut out = Vec::with_capacity(2 * 3 * k);
        for (part, values) in PARTS.iter().zip([&self.all, &self.direct]) {
            for j in 0..k {
                for (c, name) in RGB.iter().enumerate() {
                    let channel = values.iter().skip(3 * j + c).step_by(3 * k).copied();
                    out.push((format!("{part}.{j}.{name}"), channel.collect()));
                }
            }
        }
        out
    }

    /// The transfer of `pixels` pixels from a view file's channels, refusing a missing channel
    /// or a value that is not finite or beyond ±[`MAX_TRANSFER`].
    pub fn from_channels(
        basis: TransferBasis,
        pixels: usize,
        channels: &HashMap<String, Vec<f32>>,
    ) -> Result<Self> {
        let k = basis.coefficients();
        let mut parts = [vec![0.0; pixels * 3 * k], vec![0.0; pixels * 3 * k]];
        for (part, values) in PARTS.iter().zip(&mut parts) {
            for j in 0..k {
                for (c, name) in RGB.iter().enumerate() {
                    let channel = format!("{part}.{j}.{name}");
                    let v = channels.get(&channel).with_context(|| {
                        format!("lacks channel '{channel}' (--transfer {basis})")
                    })?;
                    if v.len() != pixels {
                        bail!("channel '{channel}' holds {} values, not {pixels}", v.len());
                    }
                    if let Some(p) = v.iter().position(|x| x.is_nan() || x.abs() > MAX_TRANSFER) {
                        bail!(
                            "channel '{channel}' is {:e} at pixel {p}, beyond the ±{MAX_TRANSFER} \
                             a transfer value may hold (it is packed as f16)",
                            v[p]
                        );
                    }
                    for (p, x) in v.iter().enumerate() {
                        values[p * 3 * k + 3 * j + c] = *x;
                    }
                }
            }
        }
        let [all, direct] = parts;
        Ok(Transfer { basis, all, direct })
    }

    /// Pixel `p`'s transfer as a model learns it: the whole, or (`indirect`) without its
    /// direct part.
    pub fn pixel(&self, p: usize, indirect: bool) -> impl Iterator<Item = f32> + '_ {
        let n = self.basis.floats();
        let (all, direct) = (&self.all[p * n..][..n], &self.direct[p * n..][..n]);
        all.iter()
            .zip(direct)
            .map(move |(a, d)| if indirect { a - d } else { *a })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_basis_reads_back_as_written_and_refuses_what_it_cannot_record() {
        let b: TransferBasis = "sh:2".parse().unwrap();
        assert_eq!(
            (b.band, b.coefficients(), b.to_string()),
            (2, 9, "sh:2".into())
        );
        let json = serde_json::to_string(&b).unwrap();
        assert_eq!(json, "\"sh:2\"");
        assert_eq!(serde_json::from_str::<TransferBasis>(&json).unwrap(), b);
        for bad in ["sh:9", "sh:", "learned:4", "2"] {
            assert!(bad.parse::<TransferBasis>().is_err(), "{bad}");
        }
    }

    #[test]
    fn channels_round_trip_and_a_missing_or_bad_one_is_named() {
        let basis = TransferBasis { band: 1 };
        let t = Transfer {
            basis,
            all: (0..2 * 12).map(|i| i as f32 - 5.0).collect(),
            direct: (0..2 * 12).map(|i| 0.5 * i as f32).collect(),
        };
        let channels: HashMap<String, Vec<f32>> = t.channels().into_iter().collect();
        assert_eq!(channels["transfer.3.G"], vec![5.0, 17.0]);
        assert_eq!(Transfer::from_channels(basis, 2, &channels).unwrap(), t);
        let indirect: Vec<f32> = t.pixel(1, true).collect();
        assert_eq!(indirect[0], 12.0 - 5.0 - 6.0);
        let mut missing = channels.clone();
        missing.remove("transfer_direct.2.B");
        let err = Transfer::from_channels(basis, 2, &missing).unwrap_err();
        assert!(err.to_string().contains("transfer_direct.2.B"), "{err}");
        for (bad, said) in [(f32::NAN, "NaN"), (6e4, "6e4"), (-1e30, "-1e30")] {
            let mut damaged = channels.clone();
            damaged.get_mut("transfer.0.R").unwrap()[1] = bad;
            let err = Transfer::from_channels(basis, 2, &damaged).unwrap_err();
            assert!(
                err.to_string().contains(&format!(
                    "transfer.0.R' is {said} at pixel 1, beyond the ±32752"
                )),
                "{err}"
            );
        }
        let mut largest = channels;
        largest.get_mut("transfer_direct.0.R").unwrap()[0] = -MAX_TRANSFER;
        largest.get_mut("transfer.0.R").unwrap()[0] = MAX_TRANSFER;
        let t = Transfer::from_channels(basis, 2, &largest).unwrap();
        // The largest indirect part, a difference, fits f16 (65,504).
        assert_eq!(t.pixel(0, true).next(), Some(2.0 * MAX_TRANSFER));
        assert!(half::f16::from_f32(2.0 * MAX_TRANSFER).is_finite());
    }
}
