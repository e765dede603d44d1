//! One evaluated method's results: its family, metrics over the test views, cost and error
//! analysis.

use std::path::PathBuf;

use serde::{Deserialize, Deserializer, Serialize};

use crate::metrics::Metrics;

/// Which family of method a row is: what it is compared as, and how it is run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Family {
    /// One of the paper's Neural PRT designs.
    NeuralPrt,
    /// The Deep Shading U-Net baseline.
    DeepShading,
    /// Path tracing at a fixed sample count.
    PathTracing,
    /// Path tracing denoised by Open Image Denoise: a baseline's, or the direct light a Neural
    /// PRT design traces.
    Denoised,
    /// Per-pixel spherical-harmonics PRT in a fixed view.
    ShPrt,
    /// A measurement, not a method: part of a traced design's image with the rest taken from
    /// the reference (`nprt eval --oracles`).
    Oracle,
}

/// Bins of the error analysis (directness and specularity in [0, 1]).
pub const BINS: usize = 10;

/// One method's results over the test views.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MethodResult {
    pub name: String,
    pub family: Family,
    /// Transport parameters (networks only).
    pub params: Option<usize>,
    pub mean: Metrics,
    pub per_view: Vec<Metrics>,
    /// Mean milliseconds per test view at the test resolution (what the method costs at run
    /// time: G-buffer + encoder + network for networks, tracing for path tracing, projection +
    /// dot products for SH).
    pub ms_per_view: f64,
    /// One-off precomputation per view (SH transport), milliseconds.
    pub precompute_ms: Option<f64>,
    /// Pearson correlation over foreground pixels of the per-pixel L1 error with the share of
    /// direct light, and with specularity (NaN where either is constant).
    #[serde(deserialize_with = "nan_if_null")]
    pub corr_directness: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub corr_specularity: f64,
    /// Mean per-pixel L1 error in each directness / specularity bin (NaN for an empty bin).
    #[serde(deserialize_with = "nans_if_null")]
    pub error_by_directness: Vec<f64>,
    #[serde(deserialize_with = "nans_if_null")]
    pub error_by_specularity: Vec<f64>,
    pub note: String,
    /// Training curve, for networks.
    pub loss_png: Option<PathBuf>,
    /// Validation loss against seconds of training, for networks (from their loss.csv).
    #[serde(default)]
    pub validation: Vec<(f64, f64)>,
    /// Level and tint: the prediction's foreground sum over the reference's, per channel (1 is
    /// right; a uniformly dark prediction is below 1 in all three, a wrong tint differs among
    /// them).
    #[serde(default)]
    pub level: [f64; 3],
    /// Tint error: per test view, the largest deviation of a channel's level from the view's
    /// mean level, relative to it (0 is the reference's colour balance, whatever the
    /// brightness); averaged over views. It tells a held-out map's colour rendered wrong.
    #[serde(default)]
    pub tint_error: f64,
    /// The path-tracing row of this method's own cost (Neural PRT designs, and their
    /// denoised rows), which the paper's claims compare it with.
    #[serde(default)]
    pub equal_time: Option<String>,
}

impl MethodResult {
    /// A row with no views scored yet (its level and tint unknown until they are).
    pub fn new(name: &str, family: Family, params: Option<usize>) -> Self {
        MethodResult {
            name: name.into(),
            family,
            params,
            mean: Metrics::default(),
            per_view: vec![],
            ms_per_view: 0.0,
            precompute_ms: None,
            corr_directness: 0.0,
            corr_specularity: 0.0,
            error_by_directness: vec![],
            error_by_specularity: vec![],
            note: String::new(),
            loss_png: None,
            validation: vec![],
            level: [f64::NAN; 3],
            tint_error: f64::NAN,
            equal_time: None,
        }
    }
}

/// JSON writes NaN as null; reading it back gives NaN again (so results.json round-trips).
fn nan_if_null<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// [`nan_if_null`] for each value of a list.
fn nans_if_null<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
    let values = Vec::<Option<f64>>::deserialize(d)?;
    Ok(values.into_iter().map(|v| v.unwrap_or(f64::NAN)).collect())
}
