//! The paper's orderings as training grows (`nprt paper --snapshots`): the four designs'
//! Table 5 figures at each snapshot point, each ordering of Tables 5 and 6 judged at each point
//! (the snapshot's D/S against the evaluation's competitors), the point from which each holds,
//! plots of RMSE and loss against training time with the paper's KITCHEN figures as marks, and
//! on KITCHEN each design's RMSE projected to the paper's by a power law.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;
use nprt_eval::claim::Verdict;
use nprt_eval::{mean_and_se_text, row_name, Evaluation, MethodResult, Metrics};
use nprt_net::{Design, ModelConfig};

use crate::orderings::{self, Ordering};
use crate::paper_figures::over_views;
use crate::power_law::PowerLaw;
use crate::published;
use crate::readback::GrowthPoint;

/// The evaluation with the designs' rows as kept at `point`: each row replaced by the
/// snapshot's (keeping the final row's equal-time tier, which names D/S's path-traced
/// competitor), the temporal section left out (it ran on the final models only).
fn at_point(e: &Evaluation, point: &GrowthPoint) -> Evaluation {
    let mut at = e.clone();
    at.temporal = None;
    for row in &point.rows {
        if let Some(m) = at.methods.iter_mut().find(|m| m.name == row.name) {
            let equal_time = m.equal_time.take();
            *m = MethodResult {
                equal_time,
                ..row.clone()
            };
        }
    }
    at
}

/// The orderings of Tables 5 and 6 at `point`.
fn judged_at(e: &Evaluation, point: &GrowthPoint) -> Vec<Ordering> {
    let at = at_point(e, point);
    [orderings::table5(&at), orderings::table6(&at)]
        .into_iter()
        .flatten()
        .collect()
}

/// The section of paper.md, with its plots in `dir`/images.
pub fn as_training_grows(
    md: &mut String,
    e: &Evaluation,
    points: &[GrowthPoint],
    kitchen: bool,
    dir: &Path,
) -> Result<()> {
    writeln!(md, "## The orderings as training grows\n")?;
    if points.is_empty() {
        writeln!(
            md,
            "No design kept a snapshot: the trainings finished before `--snapshots` was given \
             (a point is kept only by a run that reaches it), or none reached a point.\n"
        )?;
        return Ok(());
    }
    let designs: Vec<String> = (Design::PAPER.iter())
        .map(|&d| row_name(&ModelConfig::new(d, None)))
        .collect();
    writeln!(
        md,
        "Each design as kept at each point of its training (`--snapshots`), scored on the test \
         views: loss × 10³ / RMSE × 10³, mean with its standard error.\n"
    )?;
    writeln!(md, "| point | training min | {} |", designs.join(" | "))?;
    writeln!(md, "|---|---|{}", "---|".repeat(designs.len()))?;
    for p in points {
        write!(md, "| {} | {:.2} |", p.point, p.minutes)?;
        for name in &designs {
            match p.rows.iter().find(|m| &m.name == name) {
                Some(m) => write!(
                    md,
                    " {} / {} |",
                    e3(m, Metrics::LOG_L1),
                    e3(m, Metrics::RMSE)
                )?,
                None => write!(md, " – |")?,
            }
        }
        writeln!(md)?;
    }
    writeln!(md)?;
    verdicts(md, e, points)?;
    plots(md, points, &designs, kitchen, dir)?;
    if kitchen {
        projection(md, points, &designs)?;
    }
    Ok(())
}

/// Each design's RMSE against training time fitted by a power law, and when it would reach
/// the paper's KITCHEN RMSE if the law held.
fn projection(md: &mut String, points: &[GrowthPoint], designs: &[String]) -> Result<()> {
    writeln!(
        md,
        "### Projected: when each design would reach the paper's KITCHEN RMSE\n\n\
         A projection, not a measurement: RMSE ≈ a·t^b fitted by least squares to the \
         logarithms of the points above (t in training minutes), extended to the paper's \
         figure. It assumes the trend holds far past the last point (each run's cosine schedule \
         spans its own length; the paper trained 500 epochs at a constant rate) and sets \
         nprt's test views beside the paper's, which are other views at another size.\n"
    )?;
    writeln!(
        md,
        "| design | a × 10³ | b | R² | last point: RMSE × 10³ at min | the paper's RMSE × 10³ \
         | reached at (projected) |\n|---|---|---|---|---|---|---|"
    )?;
    for (name, &design) in designs.iter().zip(&Design::PAPER) {
        let line: Vec<(f64, f64)> = (points.iter())
            .filter_map(|p| {
                let m = p.rows.iter().find(|m| &m.name == name)?;
                Some((p.minutes, over_views(m, Metrics::RMSE).0))
            })
            .collect();
        let paper = published::table5(2, design).map(|f| f[1]);
        let (Some(fit), Some(&(t, last))) = (PowerLaw::fit(&line), line.last()) else {
            writeln!(md, "| {name} | fewer than 3 points | | | | | |")?;
            continue;
        };
        let reached = match paper.and_then(|p| fit.reaches(p / 1e3)) {
            Some(at) if fit.exponent < 0.0 => duration_of_minutes(at),
            _ => "never on this trend".into(),
        };
        writeln!(
            md,
            "| {name} | {:.2} | {:.3} | {:.2} | {:.2} at {t:.1} | {} | {reached} |",
            fit.scale * 1e3,
            fit.exponent,
            fit.r2,
            last * 1e3,
            paper.map_or("–".into(), |p| format!("{p:.2}")),
        )?;
    }
    writeln!(md)?;
    Ok(())
}

/// Minutes said in the largest unit that keeps them readable.
fn duration_of_minutes(m: f64) -> String {
    match m {
        m if m < 120.0 => format!("{m:.0} min"),
        m if m < 48.0 * 60.0 => format!("{:.1} h", m / 60.0),
        m if m < 730.0 * 24.0 * 60.0 => format!("{:.1} days", m / 1440.0),
        m => format!("{:.1e} years", m / 525_960.0),
    }
}

fn e3(m: &MethodResult, k: usize) -> String {
    mean_and_se_text(m.per_view.iter().map(|v| v.values()[k]), 1e3)
}

/// Each ordering's verdict at each point, and the point from which it holds to the last.
fn verdicts(md: &mut String, e: &Evaluation, points: &[GrowthPoint]) -> Result<()> {
    let judged: Vec<Vec<Ordering>> = points.iter().map(|p| judged_at(e, p)).collect();
    let mut statements: Vec<(&str, String)> = Vec::new();
    for o in judged.iter().flatten() {
        if !statements
            .iter()
            .any(|(t, s)| *t == o.table && *s == o.statement)
        {
            statements.push((o.table, o.statement.clone()));
        }
    }
    let labels: Vec<&str> = points.iter().map(|p| p.point.as_str()).collect();
    writeln!(
        md,
        "Each ordering at each point (✅ holds, ❌ fails, ≈ not resolved by the test views; Table 6 \
         sets the point's D/S against the final evaluation's competitors):\n"
    )?;
    writeln!(
        md,
        "| table | ordering | {} | holds from |",
        labels.join(" | ")
    )?;
    writeln!(md, "|---|---|{}---|", "---|".repeat(labels.len()))?;
    for (table, statement) in &statements {
        let verdicts: Vec<Option<Verdict>> = judged
            .iter()
            .map(|os| {
                (os.iter())
                    .find(|o| o.table == *table && &o.statement == statement)
                    .map(|o| o.verdict())
            })
            .collect();
        let marks: Vec<&str> = verdicts
            .iter()
            .map(|v| v.map_or("–", |v| v.mark()))
            .collect();
        // The first point after which it holds at every point.
        let from = (0..verdicts.len())
            .find(|&i| verdicts[i..].iter().all(|v| *v == Some(Verdict::Holds)))
            .map_or("not by the last point".to_string(), |i| {
                labels[i].to_string()
            });
        writeln!(
            md,
            "| {table} | {statement} | {} | {from} |",
            marks.join(" | ")
        )?;
    }
    writeln!(md)?;
    Ok(())
}

/// RMSE and loss against training time, per design, with the paper's KITCHEN figures as
/// horizontal marks where the scene is KITCHEN.
fn plots(
    md: &mut String,
    points: &[GrowthPoint],
    designs: &[String],
    kitchen: bool,
    dir: &Path,
) -> Result<()> {
    let minutes: Vec<f64> = points.iter().map(|p| p.minutes.max(1e-3).log2()).collect();
    let span = (
        minutes.iter().copied().fold(f64::INFINITY, f64::min),
        minutes.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    for (k, what, file) in [
        (Metrics::RMSE, "RMSE", "images/growth-rmse.png"),
        (Metrics::LOG_L1, "loss (log-L1)", "images/growth-loss.png"),
    ] {
        let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
        for (name, &design) in designs.iter().zip(&Design::PAPER) {
            let line: Vec<(f64, f64)> = (points.iter().zip(&minutes))
                .filter_map(|(p, &x)| {
                    let m = p.rows.iter().find(|m| &m.name == name)?;
                    Some((x, over_views(m, k).0))
                })
                .collect();
            series.push((name.clone(), line));
            if kitchen {
                let paper =
                    published::table5(2, design).map(|f| f[usize::from(k == Metrics::RMSE)] / 1e3);
                if let Some(v) = paper {
                    series.push((
                        format!("paper's KITCHEN {name}"),
                        vec![(span.0, v), (span.1, v)],
                    ));
                }
            }
        }
        let title = format!("{what} on the test views against training time");
        nprt_io::plot_lines(
            &dir.join(file),
            &title,
            ("training minutes, log2 (0: 1 min, 4: 16 min)", what),
            &series,
        )?;
        writeln!(md, "![{title}]({file})\n")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nprt_eval::Family;

    /// A design's row at one point: every view's RMSE `rmse`.
    fn row(name: &str, rmse: f64) -> MethodResult {
        let per_view = vec![
            Metrics {
                rmse,
                ..Metrics::default()
            };
            4
        ];
        MethodResult {
            mean: Metrics::mean(&per_view),
            per_view,
            ..MethodResult::new(name, Family::NeuralPrt, None)
        }
    }

    /// D/S on an exact power law reaches the paper's RMSE where the law says; a design that
    /// does not improve never does; one with two points is not fitted.
    #[test]
    fn each_design_is_projected_to_the_papers_kitchen_rmse() {
        let designs: Vec<String> = (Design::PAPER.iter())
            .map(|&d| row_name(&ModelConfig::new(d, None)))
            .collect();
        let paper = published::table5(2, Design::Dsep).unwrap()[1] / 1e3;
        // D/S: 4·paper at 1 minute, falling as t^-0.5: the paper's at 16 minutes.
        let points: Vec<GrowthPoint> = [1.0, 2.0, 4.0, 8.0]
            .iter()
            .enumerate()
            .map(|(i, &t): (usize, &f64)| GrowthPoint {
                point: format!("{t}m"),
                key: String::new(),
                minutes: t,
                rows: [
                    (i < 2).then(|| row(&designs[0], 0.2)),
                    Some(row(&designs[1], 0.1)),
                    Some(row(&designs[3], 4.0 * paper * t.powf(-0.5))),
                ]
                .into_iter()
                .flatten()
                .collect(),
            })
            .collect();
        let mut md = String::new();
        projection(&mut md, &points, &designs).unwrap();
        let line = |name: &str| {
            md.lines()
                .find(|l| l.starts_with(&format!("| {name} |")))
                .unwrap_or_else(|| panic!("no row for {name}:\n{md}"))
                .to_string()
        };
        // One paragraph, then a table Markdown reads as one: no line indented (4 spaces make
        // a code block), no runs of spaces, the separator right under the header.
        assert!(
            !md.lines().any(|l| l.starts_with(' ')) && !md.contains("  "),
            "{md}"
        );
        assert!(md.contains("(projected) |\n|---|"), "{md}");
        assert!(line(&designs[3]).ends_with("| 16 min |"), "{md}");
        assert!(line(&designs[3]).contains("| -0.500 | 1.00 |"), "{md}");
        assert!(
            line(&designs[1]).ends_with("| never on this trend |"),
            "{md}"
        );
        assert!(line(&designs[0]).contains("fewer than 3 points"), "{md}");
        assert!(line(&designs[2]).contains("fewer than 3 points"), "{md}");
        assert_eq!(duration_of_minutes(30.0 * 60.0), "30.0 h");
        assert_eq!(duration_of_minutes(5.0 * 1440.0), "5.0 days");
    }
}
