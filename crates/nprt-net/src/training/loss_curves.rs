//! Loss curves of a training run: a CSV table and a PNG plot.

use std::path::Path;

use anyhow::{Context, Result};
use nprt_io::plot_lines;

use serde::{Deserialize, Serialize};

/// One row of a run's loss history.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LossRow {
    pub step: u64,
    /// Epochs done, fractional.
    pub epoch: f64,
    pub samples: u64,
    pub seconds: f64,
    /// Mean training loss since the previous row (at an epoch's end that follows a row
    /// directly, that row's).
    pub train: Option<f64>,
    /// Validation loss (at epoch ends).
    pub val: Option<f64>,
}

impl LossRow {
    /// What no run writes, if the row holds it: an epoch or a time that is negative or not
    /// finite, a loss that is negative or not finite (a diverged run stops before recording
    /// one). The one check of a row, wherever one is read (loss.csv, a checkpoint's history).
    pub fn problem(&self) -> Option<String> {
        let fields = [
            ("epoch", Some(self.epoch)),
            ("seconds", Some(self.seconds)),
            ("train loss", self.train),
            ("validation loss", self.val),
        ];
        fields.into_iter().find_map(|(name, v)| match v {
            Some(v) if !(v.is_finite() && v >= 0.0) => Some(format!(
                "its {name} is {}, not a finite number ≥ 0",
                nprt_io::short_number(v)
            )),
            _ => None,
        })
    }
}

/// One loss.csv row: `step,epoch,samples,seconds,train_loss,val_loss`, empty cells where a
/// row has no value.
#[derive(Serialize, Deserialize)]
struct CsvRow {
    step: u64,
    epoch: f64,
    samples: u64,
    seconds: f64,
    train_loss: Option<f64>,
    val_loss: Option<f64>,
}

pub fn write_csv(path: &Path, rows: &[LossRow]) -> Result<()> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(CsvRow {
            step: r.step,
            epoch: r.epoch,
            samples: r.samples,
            seconds: r.seconds,
            train_loss: r.train,
            val_loss: r.val,
        })?;
    }
    nprt_io::write_file(path, w.into_inner().context("cannot finish loss.csv")?)
}

/// Rows of a loss.csv written by [`write_csv`]; none when the file does not exist. A row that
/// does not parse, or holds what no run writes ([`LossRow::problem`]), is an error naming the
/// file and the row.
pub fn read_csv(path: &Path) -> Result<Vec<LossRow>> {
    if !path.exists() {
        return Ok(vec![]);
    }
    let mut r = csv::Reader::from_path(path)
        .with_context(|| format!("cannot read '{}'", path.display()))?;
    r.deserialize::<CsvRow>()
        .enumerate()
        .map(|(i, row)| {
            let row = row.with_context(|| {
                format!("'{}': row {} is not a loss row", path.display(), i + 1)
            })?;
            let row = LossRow {
                step: row.step,
                epoch: row.epoch,
                samples: row.samples,
                seconds: row.seconds,
                train: row.train_loss,
                val: row.val_loss,
            };
            if let Some(p) = row.problem() {
                anyhow::bail!("'{}': row {}: {p}", path.display(), i + 1);
            }
            Ok(row)
        })
        .collect()
}

/// Training and validation loss against epochs, log-scaled.
pub fn plot(path: &Path, rows: &[LossRow], title: &str) -> Result<()> {
    let train: Vec<(f64, f64)> = rows
        .iter()
        .filter_map(|r| Some((r.epoch, r.train?)))
        .collect();
    let val: Vec<(f64, f64)> = rows
        .iter()
        .filter_map(|r| Some((r.epoch, r.val?)))
        .collect();
    plot_lines(
        path,
        &format!("nprt training: {title}"),
        ("epoch", "log-L1 loss"),
        &[
            ("training".into(), train),
            ("validation (held-out lighting)".into(), val),
        ],
    )
}
