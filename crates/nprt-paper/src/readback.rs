//! What `nprt paper` reads back from its own folder (experiment.json, stage-times.json,
//! report/results.json, report/table2.json, report/snapshots.json), checked as input: a file edited, truncated or left
//! by another run is refused (and its stage redone), never printed as NaN or as a time no run
//! takes. Public for the fuzz targets (fuzz/), which hold every file these accept to a report
//! without NaN or infinity.

use std::path::Path;

use anyhow::{bail, ensure, Context, Result};
use nprt_eval::{Evaluation, MethodResult};
use serde::{Deserialize, Serialize};

/// More seconds than a stage takes (a year): a record beyond it was not written by a run.
const MAX_SECONDS: f64 = 3.2e7;

/// Each stage's wall time as stage-times.json (`file`) holds it.
pub fn stage_times(bytes: &[u8], file: &Path) -> Result<Vec<(String, f64)>> {
    let times: Vec<(String, f64)> = serde_json::from_slice(bytes)
        .with_context(|| format!("'{}' is not a stage-time record", file.display()))?;
    // The report prints the names in a table: a run's own are short words.
    let plain = |n: &str| n.len() <= 64 && !n.contains(|c: char| c.is_control() || c == '|');
    if let Some((stage, _)) = times.iter().find(|(n, _)| !plain(n)) {
        bail!(
            "'{}' names a stage {stage:?} that no run names; delete it to start the record over",
            file.display()
        );
    }
    if let Some((stage, secs)) = times.iter().find(|(_, s)| !(0.0..MAX_SECONDS).contains(s)) {
        bail!(
            "'{}' says stage '{stage}' took {secs} s, which no run takes; delete it to start \
             the record over",
            file.display()
        );
    }
    Ok(times)
}

/// The experiment a folder's experiment.json (`file`) records.
pub fn experiment_record(bytes: &[u8], file: &Path) -> Result<serde_json::Value> {
    let record: serde_json::Value = serde_json::from_slice(bytes)
        .with_context(|| format!("'{}' is not an experiment record", file.display()))?;
    ensure!(
        record.is_object(),
        "'{}' is not an experiment record (not a JSON object)",
        file.display()
    );
    Ok(record)
}

/// The evaluation results.json (`file`) holds, where it is one of `views` test views and at
/// least one method beyond the `models` networks, each method with a finite figure per view.
pub fn evaluation(bytes: &[u8], file: &Path, views: usize, models: usize) -> Result<Evaluation> {
    let e: Evaluation = serde_json::from_slice(bytes)
        .with_context(|| format!("'{}' is not what this run wrote", file.display()))?;
    ensure!(
        e.test_views == views && e.methods.len() > models,
        "the kept evaluation is not this run's ({} test views, {} methods)",
        e.test_views,
        e.methods.len()
    );
    if let Some(m) = e.methods.iter().find(|m| !complete(m, Some(views))) {
        bail!("the kept evaluation's '{}' lacks figures", m.name);
    }
    Ok(e)
}

/// Table 2's runs as table2.json keeps them, with the key of their inputs.
#[derive(Serialize, Deserialize)]
pub struct Ablation {
    pub key: String,
    pub rows: Vec<MethodResult>,
}

/// Table 2's runs table2.json (`file`) holds, where every run has a finite figure per view.
pub fn ablation(bytes: &[u8], file: &Path) -> Result<Ablation> {
    let a: Ablation = serde_json::from_slice(bytes)
        .with_context(|| format!("'{}' is not what this run wrote", file.display()))?;
    if let Some(m) = a.rows.iter().find(|m| !complete(m, None)) {
        bail!("'{}': run '{}' lacks figures", file.display(), m.name);
    }
    Ok(a)
}

/// The paper's designs as kept at one snapshot point of their training, scored on the test
/// views (snapshots.json keeps one per point).
#[derive(Clone, Serialize, Deserialize)]
pub struct GrowthPoint {
    /// The point as `--snapshots` names it (`4m`, `10`).
    pub point: String,
    /// The key of the scoring's inputs (the snapshots' files among them).
    pub key: String,
    /// The designs' mean training time at the point, minutes.
    pub minutes: f64,
    pub rows: Vec<MethodResult>,
}

/// The snapshot points snapshots.json (`file`) holds, where each has a finite, non-negative
/// training time and every row a finite figure per view.
pub fn growth(bytes: &[u8], file: &Path) -> Result<Vec<GrowthPoint>> {
    let points: Vec<GrowthPoint> = serde_json::from_slice(bytes)
        .with_context(|| format!("'{}' is not what this run wrote", file.display()))?;
    for p in &points {
        ensure!(
            p.minutes.is_finite() && p.minutes >= 0.0,
            "'{}': point {} says {} minutes",
            file.display(),
            p.point,
            p.minutes
        );
        if let Some(m) = p.rows.iter().find(|m| !complete(m, None)) {
            bail!(
                "'{}': point {}'s '{}' lacks figures",
                file.display(),
                p.point,
                m.name
            );
        }
    }
    Ok(points)
}

/// Whether `m` has a finite figure per view (`views` of them, where known).
fn complete(m: &MethodResult, views: Option<usize>) -> bool {
    let finite = |v: &nprt_eval::Metrics| v.values().iter().all(|x| x.is_finite());
    !m.per_view.is_empty()
        && views.is_none_or(|n| m.per_view.len() == n)
        && m.per_view.iter().all(finite)
}
