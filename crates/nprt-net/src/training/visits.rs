//! A long run advanced a visit at a time (the pretrained KITCHEN: `bench/kitchen-visit.sh`, a
//! GPU loan's few minutes each): landing what a visit trained into the run's folder, and the
//! run's `visits.csv`, a row per visit. A visit's model is checked whole before it replaces
//! the run's (weights, config, checkpoint and a validation loss), the model lands as a folder
//! renamed into place, and the table is read back checked and written atomically: a visit
//! without a checkpoint, without a validation loss or with a NaN weight once replaced the
//! committed model and then failed.

use std::path::Path;

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

use crate::model::folder::load_model;
use crate::training::checkpoint;
use crate::training::minutes::MAX_MINUTES;

/// The run's table of visits, beside its model folder.
pub const VISITS_FILE: &str = "visits.csv";
/// The run's model folder, which each visit replaces.
pub const MODEL_DIR: &str = "model";

/// A row of `visits.csv`: when the visit landed, the run's training time (minutes on the
/// GPU) and samples and epochs done after it, and its last validation loss.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Visit {
    /// UTC, `YYYY-MM-DDTHH:MMZ`.
    pub landed: String,
    pub gpu_minutes: f64,
    pub samples: u64,
    pub epochs: u64,
    pub val_loss: f64,
}

impl Visit {
    /// The row of the model folder `model`, landed at `landed`: its checkpoint must exist and
    /// hold a validation loss (both checked as every reader of a checkpoint checks them).
    pub fn of_model(model: &Path, landed: &str) -> Result<Visit> {
        let (state, val) = checkpoint::progress(model)?.with_context(|| {
            format!(
                "'{}' holds no checkpoint/: the visit has no run to continue",
                model.display()
            )
        })?;
        let val_loss = val.with_context(|| {
            format!(
                "'{}': its checkpoint's history holds no validation loss (no epoch ended)",
                model.display()
            )
        })?;
        let visit = Visit {
            landed: landed.to_string(),
            gpu_minutes: state.seconds / 60.0,
            samples: state.samples,
            epochs: state.epoch as u64,
            val_loss,
        };
        if let Some(p) = visit.problem() {
            bail!("'{}': {p}", model.display());
        }
        Ok(visit)
    }

    /// What no visit writes, if the row holds it: the one check of a row, wherever it is read.
    pub fn problem(&self) -> Option<String> {
        if !is_utc_minute(&self.landed) {
            return Some(format!(
                "landed '{}' is not a UTC time as YYYY-MM-DDTHH:MMZ",
                self.landed.escape_debug()
            ));
        }
        if !(0.0..=MAX_MINUTES).contains(&self.gpu_minutes) {
            return Some(format!(
                "gpu_minutes {} is not from 0 to {MAX_MINUTES:e}",
                nprt_io::short_number(self.gpu_minutes)
            ));
        }
        if !(self.val_loss.is_finite() && self.val_loss >= 0.0) {
            return Some(format!(
                "val_loss {} is not a finite loss ≥ 0",
                nprt_io::short_number(self.val_loss)
            ));
        }
        None
    }
}

/// `2026-11-29T12:05Z`, each field in its calendar's range.
fn is_utc_minute(s: &str) -> bool {
    let b = s.as_bytes();
    let number = |r: std::ops::Range<usize>| -> Option<u32> {
        let digits = b.get(r)?;
        digits
            .iter()
            .all(u8::is_ascii_digit)
            .then(|| (digits.iter()).fold(0, |n, d| n * 10 + u32::from(d - b'0')))
    };
    let sep = [(4, b'-'), (7, b'-'), (10, b'T'), (13, b':'), (16, b'Z')];
    b.len() == 17
        && sep.iter().all(|&(i, c)| b[i] == c)
        && number(0..4).is_some()
        && number(5..7).is_some_and(|m| (1..=12).contains(&m))
        && number(8..10).is_some_and(|d| (1..=31).contains(&d))
        && number(11..13).is_some_and(|h| h < 24)
        && number(14..16).is_some_and(|m| m < 60)
}

/// The rows of a `visits.csv` (none where it does not exist), each checked: a row no visit
/// writes is an error naming the file, the row and the field.
pub fn read_visits(path: &Path) -> Result<Vec<Visit>> {
    if !path.exists() {
        return Ok(vec![]);
    }
    let bytes = nprt_io::read_input(path)
        .with_context(|| format!("cannot read visits '{}'", path.display()))?;
    parse_visits(&bytes).with_context(|| format!("visits '{}'", path.display()))
}

/// [`read_visits`] of the file's bytes.
pub fn parse_visits(bytes: &[u8]) -> Result<Vec<Visit>> {
    let mut reader = csv::Reader::from_reader(bytes);
    let header = reader.headers().context("no header row")?.clone();
    let expected = ["landed", "gpu_minutes", "samples", "epochs", "val_loss"];
    if !header.iter().eq(expected) {
        bail!("its header is not '{}'", expected.join(","));
    }
    let mut rows: Vec<Visit> = Vec::new();
    for (i, row) in reader.deserialize::<Visit>().enumerate() {
        let row = row.with_context(|| format!("row {} is not a visit", i + 1))?;
        if let Some(p) = row.problem() {
            bail!("row {}: {p}", i + 1);
        }
        if let Some(last) = rows.last().filter(|l| l.samples > row.samples) {
            bail!(
                "row {}: {} samples, fewer than the row before's {}: a run only goes on",
                i + 1,
                row.samples,
                last.samples
            );
        }
        rows.push(row);
    }
    Ok(rows)
}

/// The table's bytes with `rows`.
fn write_visits(path: &Path, rows: &[Visit]) -> Result<()> {
    let mut w = csv::Writer::from_writer(vec![]);
    for row in rows {
        w.serialize(row)?;
    }
    nprt_io::write_file(path, w.into_inner().context("cannot finish visits.csv")?)
}

/// Lands the visit's model folder `model` in the run folder `run` at `landed`: checks it whole
/// (it loads, with its checkpoint and a validation loss) and against the run's table (it goes
/// on from the last visit), then replaces `run/model` with it as one folder renamed into place
/// and adds its row to `run/visits.csv`. Nothing in `run` changes when a check fails.
pub fn land(model: &Path, run: &Path, landed: &str) -> Result<Visit> {
    if run.exists() && !run.is_dir() {
        bail!("--into '{}' is not a folder", run.display());
    }
    // A run folder in the model's would be copied into itself.
    if let (Ok(m), Ok(r)) = (model.canonicalize(), run.canonicalize()) {
        if r.starts_with(&m) {
            bail!(
                "--into '{}' is the model folder '{}' or inside it; land the model in the run's \
                 own folder",
                run.display(),
                model.display()
            );
        }
    }
    load_model(model).context("the visit's model does not load")?;
    let visit = Visit::of_model(model, landed)?;
    let table = run.join(VISITS_FILE);
    let mut rows = read_visits(&table)?;
    if let Some(last) = rows.last().filter(|l| l.samples > visit.samples) {
        bail!(
            "the visit's model has seen {} samples, fewer than the {} of the last visit in '{}': \
             it does not continue the run",
            visit.samples,
            last.samples,
            table.display()
        );
    }
    nprt_io::write_folder(&run.join(MODEL_DIR), |dir| copy_folder(model, dir))?;
    rows.push(visit.clone());
    write_visits(&table, &rows)?;
    Ok(visit)
}

/// Copies the files and folders in `from` into the existing folder `to`.
fn copy_folder(from: &Path, to: &Path) -> Result<()> {
    for entry in
        std::fs::read_dir(from).with_context(|| format!("cannot list '{}'", from.display()))?
    {
        let entry = entry?;
        let target = to.join(entry.file_name());
        if entry.file_type()?.is_dir() {
            std::fs::create_dir(&target)?;
            copy_folder(&entry.path(), &target)?;
        } else {
            std::fs::copy(entry.path(), &target)
                .with_context(|| format!("cannot copy '{}'", entry.path().display()))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "landed,gpu_minutes,samples,epochs,val_loss\n";

    #[test]
    fn a_table_reads_back_as_written_and_refuses_what_no_visit_writes() {
        let text = format!("{HEADER}2026-11-20T10:05Z,8.50,1000,2,0.01250\n2026-11-21T09:00Z,17.00,2000,4,0.01100\n");
        let rows = parse_visits(text.as_bytes()).unwrap();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[1].samples, 2000);
        let dir = std::env::temp_dir().join(format!("nprt-visits-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write_visits(&dir.join(VISITS_FILE), &rows).unwrap();
        assert_eq!(read_visits(&dir.join(VISITS_FILE)).unwrap(), rows);
        std::fs::remove_dir_all(&dir).unwrap();
        for (row, said) in [
            ("2026-11-20T10:05Z,nan,1000,2,0.0125", "gpu_minutes NaN"),
            ("2026-11-20T10:05Z,-1,1000,2,0.0125", "gpu_minutes -1"),
            ("2026-11-20T10:05Z,1e300,1000,2,0.0125", "gpu_minutes 1e300"),
            ("2026-11-20T10:05Z,8.5,1000,2,NaN", "val_loss NaN"),
            ("2026-11-20T10:05Z,8.5,1000,2,inf", "val_loss inf"),
            (
                "2026-13-20T10:05Z,8.5,1000,2,0.01",
                "landed '2026-13-20T10:05Z'",
            ),
            ("yesterday,8.5,1000,2,0.01", "landed 'yesterday'"),
            ("2026-11-20T10:05Z,8.5,-5,2,0.01", "row 1 is not a visit"),
            ("2026-11-20T10:05Z,8.5,1000,2", "row 1 is not a visit"),
        ] {
            let err = format!(
                "{:#}",
                parse_visits(format!("{HEADER}{row}\n").as_bytes()).unwrap_err()
            );
            assert!(err.contains(said), "{row}: {err}");
        }
        let back =
            format!("{HEADER}2026-11-20T10:05Z,8.5,2000,2,0.01\n2026-11-21T10:05Z,9,1000,3,0.01\n");
        let err = parse_visits(back.as_bytes()).unwrap_err().to_string();
        assert!(err.contains("fewer than the row before's 2000"), "{err}");
        let err = parse_visits(b"when,minutes\n").unwrap_err().to_string();
        assert!(err.contains("header"), "{err}");
    }
}
