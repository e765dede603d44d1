//! The paper's tables as one report (paper.md, and paper.html with its images embedded) beside
//! the evaluation's own report: each table with the paper's figures where nprt holds them, each
//! ordering the paper states judged, crops of every design at the same pixels, the training
//! curves, and a paragraph generated from the judgements.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Result;
use nprt_eval::claim::Verdict;
use nprt_eval::{
    crop_image, markdown_to_html, mean_and_se_text, plot_validation, row_name, Evaluation,
    MethodResult, Metrics, VALIDATION_PLOT,
};
use nprt_net::{Design, ModelConfig};

use crate::experiment::{beyond_the_paper, Experiment};
use crate::growth_report;
use crate::orderings::{self, ablation_configs, test_view_competitors, Ordering};
use crate::paper_figures::{self, design_row, over_views};
use crate::published;
use crate::readback::GrowthPoint;

/// Writes paper.md and paper.html into `dir` (the evaluation's report folder, whose images the
/// crops are); returns their paths.
pub fn write_paper_report(
    x: &Experiment,
    e: &Evaluation,
    (ablation, growth): (&[MethodResult], &[GrowthPoint]),
    times: &[(String, f64)],
    dir: &Path,
) -> Result<(PathBuf, PathBuf)> {
    let kitchen = x.scene.to_lowercase().contains("kitchen");
    let mut md = String::new();
    header(&mut md, x, e)?;
    md += &stage_table(times)?;
    md += &report_tables(e, ablation, kitchen)?;
    if !x.snapshots.is_empty() {
        growth_report::as_training_grows(&mut md, e, growth, kitchen, dir)?;
    }
    crops(&mut md, e, dir)?;
    curves(&mut md, ablation, dir)?;
    writeln!(
        md,
        "## Where the paper's figures come from\n\n{}. The paper's scenes are its own (ATELIER, \
         BEDROOM, KITCHEN, SANMIGUEL), labelled as the paper's; the ratios compare across scenes.",
        crate::published::SOURCE
    )?;
    let md_path = dir.join("paper.md");
    nprt_io::write_file(&md_path, &md)?;
    let html_path = dir.join("paper.html");
    nprt_io::write_file(
        &html_path,
        markdown_to_html(&md, dir, "nprt: the paper's tables")?,
    )?;
    Ok((md_path, html_path))
}

fn header(md: &mut String, x: &Experiment, e: &Evaluation) -> Result<()> {
    let b = &x.budget;
    writeln!(
        md,
        "# The paper's tables on `{}`, budget `{}`\n",
        x.scene, b.name
    )?;
    writeln!(
        md,
        "Lighting `{}`. The budget takes {}{}. Dataset: {} training views of {}² at {} spp; {} test views of {}² under \
         held-out lighting, references at {} spp. Networks trained {} each on the {} ({} CPU \
         threads). Every figure below is a mean over the test views with its standard error, and \
         every ordering is judged on per-view (or per-frame) differences: ✅ holds (two standard \
         errors in its favour), ❌ fails (two against), ≈ not resolved by these views. The \
         evaluation's full report (every method, error analysis, temporal section) is \
         [report.html](report.html).\n",
        x.envmaps,
        b.wall_time,
        match x.training_minutes {
            Some(m) => format!(
                " with its own training ({} a network); this run trains {} \
                 (--training-minutes)",
                describe_run(b.training),
                match b.training.minutes {
                    Some(own) if own == m => "as long",
                    Some(own) if own > m => "shorter",
                    _ => "longer",
                }
            ),
            None => String::new(),
        },
        b.train_views,
        b.train_res,
        b.spp,
        e.test_views,
        e.resolution[0],
        e.reference_spp,
        describe_run(x.training()),
        x.engine.name(),
        e.cpu_threads
    )?;
    Ok(())
}

/// The table of each stage's wall time and their sum.
pub fn stage_table(times: &[(String, f64)]) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "| stage | wall time |\n|---|---|")?;
    for (stage, secs) in times {
        writeln!(md, "| {stage} | {} |", duration(*secs))?;
    }
    // From +0: an empty sum of f64 is −0, printed "-0 s" (found by the paper_stage_times target).
    let all = times.iter().fold(0.0, |sum, (_, t)| sum + t);
    writeln!(md, "| **all** | **{}** |\n", duration(all))?;
    Ok(md)
}

/// The report's judgements and tables from the evaluation and Table 2's runs alone (what `nprt
/// paper` reads back from results.json and table2.json): the summary, Tables 1 to 6 beside the
/// paper's figures, and the orderings in the paper's own numbers. `kitchen`: the scene is the
/// paper's KITCHEN, whose published row is then set beside nprt's.
pub fn report_tables(e: &Evaluation, ablation: &[MethodResult], kitchen: bool) -> Result<String> {
    let orderings = orderings::all(e, ablation);
    let mut md = String::new();
    summary(&mut md, &orderings)?;
    table1(&mut md, e, ablation)?;
    table2(&mut md, ablation, &orderings)?;
    tables34(&mut md, e)?;
    table5(&mut md, e, kitchen, &orderings)?;
    table6(&mut md, e, &orderings)?;
    paper_figures::papers_own_orderings(&mut md)?;
    Ok(md)
}

fn describe_run(r: nprt_net::RunLength) -> String {
    match (r.epochs, r.minutes) {
        (Some(e), _) => format!("{e} epochs"),
        (None, Some(m)) => format!("{} minutes", nprt_io::short_number(m)),
        (None, None) => "the default schedule".into(),
    }
}

fn duration(secs: f64) -> String {
    // −0 (a record may hold it) is said as 0.
    let secs = secs + 0.0;
    if secs < 90.0 {
        format!("{secs:.0} s")
    } else {
        format!("{:.1} min", secs / 60.0)
    }
}

/// The paragraph the judgements make: how many orderings hold, and what fails by how much.
fn summary(md: &mut String, orderings: &[Ordering]) -> Result<()> {
    writeln!(md, "## What this run says\n")?;
    let count = |v: Verdict| orderings.iter().filter(|o| o.verdict() == v).count();
    write!(
        md,
        "Of the {} orderings the paper states that this run tests, {} hold, {} fail and {} are not resolved by its test views.",
        orderings.len(),
        count(Verdict::Holds),
        count(Verdict::Fails),
        count(Verdict::Unresolved)
    )?;
    writeln!(md, "\n")?;
    for table in ["Table 2", "Table 5", "Table 6"] {
        for o in orderings.iter().filter(|o| o.table == table) {
            let how = match o.verdict() {
                Verdict::Holds => "holds".to_string(),
                v => format!("{}: {}", v.word(), o.breakdown()),
            };
            writeln!(md, "- {table}: {} — {how}.", o.statement)?;
        }
    }
    writeln!(md)?;
    Ok(())
}

/// The judged orderings of one table, each with its comparisons.
fn judged(md: &mut String, orderings: &[Ordering], table: &str) -> Result<()> {
    for o in orderings.iter().filter(|o| o.table == table) {
        writeln!(
            md,
            "- {} **{}**: {}",
            o.verdict().mark(),
            o.statement,
            o.verdict().word()
        )?;
        for c in &o.comparisons {
            writeln!(md, "  - {} {}", c.claim.verdict.mark(), c.claim.text)?;
        }
    }
    writeln!(md)?;
    Ok(())
}

/// [`over_views`] × 10³, as the paper prints it.
fn e3(m: &MethodResult, k: usize) -> String {
    mean_and_se_text(m.per_view.iter().map(|v| v.values()[k]), 1e3)
}

fn table1(md: &mut String, e: &Evaluation, ablation: &[MethodResult]) -> Result<()> {
    writeln!(
        md,
        "## Table 1: transport parameters (the light encoder excluded)\n"
    )?;
    writeln!(md, "| model | nprt | paper |\n|---|---|---|")?;
    for d in Design::PAPER {
        if let Some(m) = design_row(e, d) {
            writeln!(md, "| {} | {} | {} |", m.name, params(m), d.paper_params())?;
        }
    }
    for m in ablation.iter().filter(|m| e.method(&m.name).is_none()) {
        writeln!(md, "| {} | {} | – |", m.name, params(m))?;
    }
    if let Some(m) = e.method("deep-shading") {
        writeln!(md, "| {} (U-Net) | {} | – |", m.name, params(m))?;
    }
    if let Some(m) = design_row(e, Design::Dsep) {
        writeln!(
            md,
            "\nD/S's two tracks of width 172, as the paper describes them, count {} parameters; \
             its table gives about {} (docs/model.md).",
            params(m),
            Design::Dsep.paper_params()
        )?;
    }
    writeln!(md)?;
    Ok(())
}

fn params(m: &MethodResult) -> String {
    m.params.map_or("–".into(), |p| p.to_string())
}

fn table2(md: &mut String, ablation: &[MethodResult], orderings: &[Ordering]) -> Result<()> {
    writeln!(
        md,
        "## Table 2: SIREN or ReLU in the baseline and the PRT-inspired design\n"
    )?;
    writeln!(
        md,
        "Each run trained the same budget. Loss: the log-L1 training loss on the test views (held-out \
         lighting); the last column is the training's own validation loss at its end.\n"
    )?;
    writeln!(
        md,
        "| run | model | loss × 10³ | RMSE × 10³ | training's validation loss × 10³ |\n|---|---|---|---|---|"
    )?;
    for (c, label) in ablation_configs().iter().zip(paper_figures::TABLE2_RUNS) {
        let Some(m) = ablation.iter().find(|m| m.name == row_name(c)) else {
            continue;
        };
        let val = m
            .validation
            .last()
            .map_or("–".into(), |(_, v)| format!("{:.2}", 1e3 * v));
        writeln!(
            md,
            "| {label} | {} | {} | {} | {val} |",
            m.name,
            e3(m, Metrics::LOG_L1),
            e3(m, Metrics::RMSE)
        )?;
    }
    writeln!(md)?;
    paper_figures::table2(md, ablation)?;
    judged(md, orderings, "Table 2")
}

fn tables34(md: &mut String, e: &Evaluation) -> Result<()> {
    writeln!(
        md,
        "## Tables 3 and 4: milliseconds per {0}×{0} frame\n\nHere on the {1} threads' CPU (median of three runs); the paper's on an RTX 3090 at 512².\n",
        e.timing_res, e.cpu_threads
    )?;
    writeln!(md, "| stage | nprt ms | paper ms |\n|---|---|---|")?;
    for t in &e.timings {
        writeln!(md, "| {} | {:.1} | {} |", t.what, t.ms, paper_ms(&t.what))?;
    }
    writeln!(md)?;
    Ok(())
}

/// The paper's time for a timing row, where it gives one.
fn paper_ms(what: &str) -> String {
    if what.starts_with("path tracing, 5 spp") {
        let ms = published::PATH_TRACING_5SPP_MS;
        let (lo, hi) = (
            ms.iter().copied().fold(f64::MAX, f64::min),
            ms.iter().copied().fold(0.0, f64::max),
        );
        return format!("{lo:.0}–{hi:.0} (Falcor)");
    }
    for d in Design::PAPER {
        let name = row_name(&ModelConfig::new(d, None));
        if what == format!("{name}: encoder") {
            return format!("{:.2}", published::ENCODER_MS);
        }
        if what == format!("{name}: network") {
            return published::network_ms(d).map_or("–".into(), |ms| format!("{ms:.2}"));
        }
    }
    "–".into()
}

fn table5(md: &mut String, e: &Evaluation, kitchen: bool, orderings: &[Ordering]) -> Result<()> {
    writeln!(md, "## Table 5: the four designs\n")?;
    writeln!(
        md,
        "Absolute figures depend on the maps and the exposure, which differ from the paper's; the \
         ratios to D/S compare.\n"
    )?;
    writeln!(
        md,
        "| design | loss × 10³ | RMSE × 10³ | RMSE / D/S's |\n|---|---|---|---|"
    )?;
    let rmse = |m: &MethodResult| over_views(m, Metrics::RMSE).0;
    let ds = design_row(e, Design::Dsep).map(rmse);
    for d in Design::PAPER {
        let Some(m) = design_row(e, d) else { continue };
        let ratio = ds.map_or("–".into(), |r| format!("{:.3}", rmse(m) / r));
        writeln!(
            md,
            "| {} | {} | {} | {ratio} |",
            m.name,
            e3(m, Metrics::LOG_L1),
            e3(m, Metrics::RMSE)
        )?;
    }
    writeln!(md)?;
    paper_figures::table5(md, e, kitchen)?;
    judged(md, orderings, "Table 5")
}

fn table6(md: &mut String, e: &Evaluation, orderings: &[Ordering]) -> Result<()> {
    writeln!(md, "## Table 6: D/S against every competitor\n")?;
    writeln!(md, "On the {} test views:\n", e.test_views)?;
    let beyond = row_name(&beyond_the_paper());
    let names: Vec<String> = design_row(e, Design::Dsep)
        .map(|ds| {
            let mut rows = vec![ds.name.clone(), beyond.clone()];
            rows.extend(test_view_competitors(ds));
            rows
        })
        .unwrap_or_default();
    nprt_eval::table6(
        md,
        names
            .iter()
            .filter_map(|n| e.method(n))
            .map(|m| (m.name.as_str(), m.per_view.as_slice())),
    )?;
    if e.method(&beyond).is_some() {
        writeln!(
            md,
            "{beyond} is beyond the paper: D/S's tracks made linear in the lighting (each \
             shading network a transfer matrix dotted with the map's spherical harmonics to band \
             2), its direct light traced in its time (docs/model.md). The orderings below judge \
             D/S alone.\n"
        )?;
    }
    if let Some(t) = &e.temporal {
        writeln!(
            md,
            "Along the camera path ({} frames at {}², the lighting changing at frame {}), where the \
             radiance caches (NRC, NRC-CACHE) train online:\n",
            t.frames, t.resolution[0], t.change_at
        )?;
        nprt_eval::table6(
            md,
            t.methods
                .iter()
                .map(|m| (m.name.as_str(), m.per_frame.as_slice())),
        )?;
    }
    paper_figures::table6(md, e)?;
    judged(md, orderings, "Table 6")
}

/// Figs. 7 and 9: every design and the main baselines on the same pixels of each shown view.
fn crops(md: &mut String, e: &Evaluation, dir: &Path) -> Result<()> {
    writeln!(md, "## Figures 7 and 9: crops at the same pixels\n")?;
    let ds = design_row(e, Design::Dsep);
    let pt = ds.and_then(|m| m.equal_time.clone()).unwrap_or_default();
    let mut names: Vec<String> = vec!["reference".into()];
    names.extend(
        Design::PAPER
            .iter()
            .filter_map(|&d| design_row(e, d))
            .map(|m| m.name.clone()),
    );
    names.extend([
        "deep-shading".into(),
        pt.clone(),
        format!("{pt} + OIDN"),
        "sh-prt-9".into(),
    ]);
    names.retain(|n| {
        e.shown_views
            .iter()
            .any(|&v| dir.join(crop_image(v, n)).is_file())
    });
    writeln!(
        md,
        "| view | {} |\n|---|{}",
        names.join(" | "),
        "---|".repeat(names.len())
    )?;
    for &v in &e.shown_views {
        write!(md, "| {v} |")?;
        for n in &names {
            let image = crop_image(v, n);
            if dir.join(&image).is_file() {
                write!(md, " ![]({image}) |")?;
            } else {
                write!(md, " – |")?;
            }
        }
        writeln!(md)?;
    }
    writeln!(md)?;
    Ok(())
}

/// Validation loss against training time: Table 5's networks (the evaluation's plot) and
/// Table 2's runs.
fn curves(md: &mut String, ablation: &[MethodResult], dir: &Path) -> Result<()> {
    writeln!(md, "## Training curves\n")?;
    if dir.join(VALIDATION_PLOT).is_file() {
        writeln!(md, "![the designs' validation loss]({VALIDATION_PLOT})\n")?;
    }
    let rel = "images/table2-validation.png";
    let title = "Table 2's runs: validation loss against training time";
    if plot_validation(ablation, &dir.join(rel), title)? {
        writeln!(md, "![Table 2's validation loss]({rel})\n")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An empty record and a record of −0 s print 0 s (the `paper_stage_times` fuzz target
    /// found "**-0 s**").
    #[test]
    fn stage_times_never_print_a_negative_zero() {
        for times in [vec![], vec![("dataset".to_string(), -0.0)]] {
            let md = stage_table(&times).unwrap();
            assert!(
                !md.contains("-0") && md.contains("| **all** | **0 s** |"),
                "{md}"
            );
        }
    }
}
