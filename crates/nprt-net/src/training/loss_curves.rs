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
/// does not parse is an error naming the file and the row.
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
            Ok(LossRow {
                step: row.step,
                epoch: row.epoch,
                samples: row.samples,
                seconds: row.seconds,
                train: row.train_loss,
                val: row.val_loss,
            })
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
