//! The paper's own figures in the report, beside nprt's: its Table 2 (ATELIER, BEDROOM), its
//! Table 5 (all four scenes), its Table 6 (ATELIER, BEDROOM, every competitor), each with the
//! scale-free ratios a reader can compare on any scene (each design to D/S, each competitor
//! to D/S, each run of Table 2 to PRT-inspired (S)), and whether each ordering the paper states
//! holds in the paper's own numbers. The paper's scenes are labelled as the paper's.

use std::fmt::Write as _;

use anyhow::Result;
use nprt_eval::{mean_and_se, row_name, Evaluation, MethodResult, Metrics};
use nprt_net::{Design, ModelConfig};

use crate::orderings::{ablation_configs, test_view_competitors};
use crate::published::{self, SCENES, TABLE2, TABLE2_SCENES, TABLE5, TABLE6, TABLE6_METHODS};

/// Table 2's runs, in `ablation_configs`' order, as the paper names them.
pub const TABLE2_RUNS: [&str; 4] = [
    "baseline (R)",
    "baseline (S)",
    "PRT-inspired (R)",
    "PRT-inspired (S)",
];

/// The mean of metric `k` over `m`'s views and its standard error.
pub(crate) fn over_views(m: &MethodResult, k: usize) -> (f64, f64) {
    mean_and_se(m.per_view.iter().map(|v| v.values()[k]))
}

/// `d`'s row (with its own default activation) of the evaluation.
pub(crate) fn design_row(e: &Evaluation, d: Design) -> Option<&MethodResult> {
    e.method(&row_name(&ModelConfig::new(d, None)))
}

/// `a / b` with three decimals, or "–" where either is missing or `b` is not positive.
fn ratio(a: Option<f64>, b: Option<f64>) -> String {
    match (a, b) {
        (Some(a), Some(b)) if b > 0.0 && a.is_finite() && b.is_finite() => format!("{:.3}", a / b),
        _ => "–".into(),
    }
}

/// The mean of metric `k` over `m`'s views, where it has views.
fn mean(m: Option<&MethodResult>, k: usize) -> Option<f64> {
    let m = m.filter(|m| !m.per_view.is_empty())?;
    Some(over_views(m, k).0)
}

/// Table 2 relative to PRT-inspired (S): nprt's runs and the paper's in each of its scenes.
pub fn table2(md: &mut String, ablation: &[MethodResult]) -> Result<()> {
    let runs: Vec<Option<&MethodResult>> = (ablation_configs().iter())
        .map(|c| ablation.iter().find(|m| m.name == row_name(c)))
        .collect();
    writeln!(
        md,
        "The paper's Table 2 (its scenes, not this one), × 10³ (it prints the RMSE as a fraction, \
         0.058 for 58 × 10³), and every figure relative to PRT-inspired (S)'s in the same \
         column, nprt's beside the paper's:\n"
    )?;
    write!(
        md,
        "| run | nprt loss / PRT (S)'s | nprt RMSE / PRT (S)'s |"
    )?;
    for s in TABLE2_SCENES {
        write!(
            md,
            " paper {s} loss × 10³ | RMSE × 10³ | loss / PRT (S)'s | RMSE / PRT (S)'s |"
        )?;
    }
    writeln!(
        md,
        "\n|---|---|---|{}",
        "---|".repeat(4 * TABLE2_SCENES.len())
    )?;
    let last = runs.len() - 1;
    for (i, run) in TABLE2_RUNS.iter().enumerate() {
        let nprt =
            [Metrics::LOG_L1, Metrics::RMSE].map(|k| ratio(mean(runs[i], k), mean(runs[last], k)));
        write!(md, "| {run} | {} | {} |", nprt[0], nprt[1])?;
        for (s, _) in TABLE2_SCENES.iter().enumerate() {
            let [loss, rmse] = TABLE2[i][s];
            let [l0, r0] = TABLE2[last][s];
            let (lr, rr) = (ratio(Some(loss), Some(l0)), ratio(Some(rmse), Some(r0)));
            write!(md, " {loss:.1} | {rmse:.0} | {lr} | {rr} |")?;
        }
        writeln!(md)?;
    }
    writeln!(md)?;
    Ok(())
}

/// Table 5 relative to D/S: nprt's designs beside the paper's in each of its four scenes.
pub fn table5(md: &mut String, e: &Evaluation, kitchen: bool) -> Result<()> {
    let row = |d: Design| design_row(e, d);
    let ds = row(Design::Dsep);
    let here = if kitchen {
        "this run's scene is the paper's KITCHEN"
    } else {
        "none of them is this run's scene"
    };
    writeln!(
        md,
        "The paper's Table 5 in its four scenes ({here}), × 10³, and each design's figure \
         relative to D/S's in the same column, nprt's beside the paper's:\n"
    )?;
    write!(md, "| design | nprt loss / D/S's | nprt RMSE / D/S's |")?;
    for s in SCENES {
        write!(md, " paper {s} loss | RMSE | loss / D/S's | RMSE / D/S's |")?;
    }
    writeln!(md, "\n|---|---|---|{}", "---|".repeat(4 * SCENES.len()))?;
    for d in Design::PAPER {
        let nprt = [Metrics::LOG_L1, Metrics::RMSE].map(|k| ratio(mean(row(d), k), mean(ds, k)));
        let name = row(d).map_or(d.name().to_string(), |m| m.name.clone());
        write!(md, "| {name} | {} | {} |", nprt[0], nprt[1])?;
        for s in 0..SCENES.len() {
            let (Some([loss, rmse]), Some([l0, r0])) =
                (published::table5(s, d), published::table5(s, Design::Dsep))
            else {
                continue;
            };
            let (lr, rr) = (ratio(Some(loss), Some(l0)), ratio(Some(rmse), Some(r0)));
            write!(md, " {loss:.2} | {rmse:.1} | {lr} | {rr} |")?;
        }
        writeln!(md)?;
    }
    writeln!(md)?;
    Ok(())
}

/// Table 6 relative to D/S: each competitor's figure over D/S's, per metric, on nprt's test
/// views and in the paper's two scenes, then the paper's own figures.
pub fn table6(md: &mut String, e: &Evaluation) -> Result<()> {
    let Some(ds) = design_row(e, Design::Dsep) else {
        return Ok(());
    };
    let names = || Metrics::TABLE6.map(|k| Metrics::NAMES[k]).join(" | ");
    writeln!(
        md,
        "Each competitor's figure relative to D/S's (above 1: D/S is ahead), per metric, on this \
         run's test views:\n"
    )?;
    writeln!(md, "| method | {} |\n|---|{}", names(), "---|".repeat(5))?;
    for name in test_view_competitors(ds) {
        let Some(m) = e.method(&name) else { continue };
        let cells: Vec<String> = (Metrics::TABLE6.iter())
            .map(|&k| ratio(mean(Some(m), k), mean(Some(ds), k)))
            .collect();
        writeln!(md, "| {name} | {} |", cells.join(" | "))?;
    }
    writeln!(md)?;
    let last = TABLE6_METHODS.len() - 1;
    for (scene, rows) in TABLE6 {
        writeln!(
            md,
            "The paper's Table 6 on its {scene} (× 10³ over a camera path; PRT: one frame), and \
             each figure relative to its D/S's:\n"
        )?;
        writeln!(
            md,
            "| paper's method | {} | {} |\n|---|{}",
            names(),
            names().replace(" |", " / D/S's |") + " / D/S's",
            "---|".repeat(10)
        )?;
        for (method, figures) in TABLE6_METHODS.iter().zip(rows) {
            let values: Vec<String> = figures.iter().map(|v| format!("{v:.2}")).collect();
            let ratios: Vec<String> = (figures.iter().zip(rows[last]))
                .map(|(v, d)| ratio(Some(*v), Some(d)))
                .collect();
            writeln!(
                md,
                "| {method} | {} | {} |",
                values.join(" | "),
                ratios.join(" | ")
            )?;
        }
        writeln!(md)?;
    }
    writeln!(
        md,
        "The paper's RTPT + denoise ran another denoiser (with a manual colour correction) and is \
         worse than its RTPT alone; nprt's denoised row is OIDN's. nprt's equal-time budget is \
         measured on nprt's own engine, the paper's (5 spp) on an RTX 3090.\n"
    )?;
    Ok(())
}

/// Whether each ordering the paper states holds in the paper's own printed figures.
pub fn papers_own_orderings(md: &mut String) -> Result<()> {
    writeln!(md, "## The paper's orderings in its own figures\n")?;
    let verdict = |holds: bool| if holds { "holds" } else { "fails" };
    for (s, scene) in TABLE2_SCENES.iter().enumerate() {
        for (c, column) in ["loss", "RMSE"].iter().enumerate() {
            let v: Vec<f64> = TABLE2.iter().map(|run| run[s][c]).collect();
            let lowest = v.iter().all(|&x| v[3] <= x);
            let highest = v.iter().all(|&x| v[1] >= x);
            writeln!(
                md,
                "- Table 2, {scene}, {column}: PRT-inspired (S) lowest {}; baseline (S) highest {}.",
                verdict(lowest),
                verdict(highest)
            )?;
        }
    }
    for (s, scene) in SCENES.iter().enumerate() {
        for (c, column) in ["loss", "RMSE"].iter().enumerate() {
            let v: Vec<f64> = TABLE5[s].iter().map(|d| d[c]).collect();
            let ds_lowest = v.iter().all(|&x| v[3] <= x);
            let order = v[2] <= v[1] && v[1] < v[0];
            writeln!(
                md,
                "- Table 5, {scene}, {column}: D/S lowest {}; albedo ≤ PRT-inspired < baseline {}.",
                verdict(ds_lowest),
                verdict(order)
            )?;
        }
    }
    let last = TABLE6_METHODS.len() - 1;
    for (scene, rows) in TABLE6 {
        // Judged as printed: BEDROOM's MRSE, where PRT-25 is below D/S, is the paper's own
        // stated exception.
        let mut exceptions = Vec::new();
        for (k, &metric) in Metrics::TABLE6.iter().enumerate() {
            let ds = rows[last][k];
            for (method, figures) in TABLE6_METHODS.iter().zip(&rows[..last]) {
                if figures[k] < ds {
                    let name = Metrics::NAMES[metric];
                    exceptions.push(format!(
                        "{name}: {method} {:.2} against {ds:.2}",
                        figures[k]
                    ));
                }
            }
        }
        match exceptions.is_empty() {
            true => writeln!(md, "- Table 6, {scene}: D/S lowest in every metric holds.")?,
            false => writeln!(
                md,
                "- Table 6, {scene}: D/S lowest in every metric fails ({}).",
                exceptions.join("; ")
            )?,
        }
    }
    writeln!(md)?;
    Ok(())
}
