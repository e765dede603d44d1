//! The evaluation as a report folder: report.md (images beside it), report.html (the same,
//! self-contained with embedded images) and results.json.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use nprt_io::plot_lines;
use nprt_io::write_file;

mod html;
mod pictures;
mod table6;
mod temporal_section;

pub use html::markdown_to_html;
pub use pictures::auto_exposure;
use pictures::{crop, crop_window, heat_map, save, with_background, HEAT_MAX, ZOOM};
pub use table6::{mean_and_se, mean_and_se_text, table6};

use crate::evaluate::Evaluation;
use crate::method::{MethodResult, BINS};
use crate::metrics::{Metrics, RELATIVE_EPS};

/// A method name as a file-name part.
pub(super) fn slug(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect()
}

pub(super) fn fmt(v: f64) -> String {
    if !v.is_finite() {
        "–".into()
    } else if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e4) {
        format!("{v:.3e}")
    } else {
        format!("{v:.4}")
    }
}

/// Writes the report folder; returns the paths of report.md and report.html.
pub fn write_report(e: &Evaluation, dir: &Path) -> Result<(PathBuf, PathBuf)> {
    std::fs::create_dir_all(dir.join("images"))
        .with_context(|| format!("cannot create report folder '{}'", dir.display()))?;
    let mut md = String::new();
    writeln!(md, "# nprt evaluation\n")?;
    writeln!(
        md,
        "Scene `{}`, dataset `{}`: {} test views at {}×{} under held-out lighting ({} foreground pixels). \
         All metrics on linear radiance over foreground pixels, averaged over views (see docs/evaluation.md). \
         Times on this machine ({} threads).\n",
        e.scene,
        e.data.display(),
        e.test_views,
        e.resolution[0],
        e.resolution[1],
        e.foreground_pixels,
        e.cpu_threads
    )?;
    errors(&mut md, e)?;
    claims(&mut md, e)?;
    timings(&mut md, e)?;
    error_analysis(&mut md, e, dir)?;
    temporal_section::temporal(&mut md, e, dir)?;
    images(&mut md, e, dir)?;
    training_curves(&mut md, e, dir)?;
    let md_path = dir.join("report.md");
    write_file(&md_path, &md)?;
    let html_path = dir.join("report.html");
    let html = markdown_to_html(&md, dir, "nprt evaluation")?;
    write_file(&html_path, html)?;
    let json = serde_json::to_vec_pretty(e)?;
    write_file(&dir.join("results.json"), &json)?;
    Ok((md_path, html_path))
}

/// The error table (the paper's Tables 5 and 6) and the notes under it.
fn errors(md: &mut String, e: &Evaluation) -> Result<()> {
    writeln!(md, "## Errors (the paper's Tables 5 and 6)\n")?;
    write!(md, "| method | params |")?;
    for n in Metrics::NAMES {
        write!(md, " {n} |")?;
    }
    writeln!(
        md,
        " ms / view | level R / G / B | tint error |\n|---|---|{}---|---|---|",
        "---|".repeat(Metrics::NAMES.len())
    )?;
    for m in &e.methods {
        write!(
            md,
            "| {} | {} |",
            m.name,
            m.params.map_or("–".into(), |p| p.to_string())
        )?;
        for v in m.mean.values() {
            write!(md, " {} |", fmt(v))?;
        }
        let [r, g, b] = m.level;
        writeln!(
            md,
            " {:.1} | {r:.3} / {g:.3} / {b:.3} | {:.3} |",
            m.ms_per_view, m.tint_error
        )?;
    }
    if let Some(floor) = &e.noise_floor {
        write!(md, "| *reference noise floor* | – |")?;
        for v in floor.values() {
            write!(md, " {} |", fmt(v))?;
        }
        writeln!(md, " – | – | – |")?;
    }
    writeln!(md)?;
    writeln!(
        md,
        "Table 6's metrics as the paper prints them (× 10³), each with its standard error over \
         the {} test views. The paper's own figures are for its scenes (ATELIER, BEDROOM, \
         KITCHEN, SANMIGUEL); scene `{}` is not one of them, and nprt's KITCHEN is not in its \
         Table 6 either, so none are set beside these.\n",
        e.test_views, e.scene
    )?;
    table6::table6(
        md,
        e.methods
            .iter()
            .map(|m| (m.name.as_str(), m.per_view.as_slice())),
    )?;
    noise_floor_note(md, e)?;
    for m in e.methods.iter().filter(|m| !m.note.is_empty()) {
        writeln!(md, "- {}: {}", m.name, m.note)?;
    }
    if let Some(p) = e.methods.iter().find_map(|m| m.precompute_ms) {
        writeln!(
            md,
            "- SH transport precomputation: {:.0} ms per view (not counted in ms / view).",
            p
        )?;
    }
    writeln!(
        md,
        "- Level R / G / B: each channel's sum of the prediction over the reference's, on the \
         foreground of every test view; 1 is right, below 1 in all three is too dark, unequal \
         values are a wrong tint. Tint error: per view, the largest deviation of a channel's \
         level from the mean of the three, relative to it, averaged over views (0 is the \
         reference's colour balance at any brightness)."
    )?;
    writeln!(md, "- Denoiser: {}.\n", e.denoiser)?;
    Ok(())
}

/// What the references' noise floor means here, or why it is unknown.
fn noise_floor_note(md: &mut String, e: &Evaluation) -> Result<()> {
    let Some(floor) = &e.noise_floor else {
        return Ok(writeln!(
            md,
            "- Reference noise floor: unknown; the test views ({} spp) were not rendered in two halves \
             (a dataset from before `nprt generate --test-spp`).",
            e.reference_spp
        )?);
    };
    let best = e
        .methods
        .iter()
        .map(|m| m.mean.l1)
        .fold(f64::INFINITY, f64::min);
    writeln!(
        md,
        "- Reference noise floor: the references ({} spp) have noise of their own; the first half of \
         each reference's samples differs from the whole by noise of the same size, and its error is \
         the row above. A method's measured error mixes its own with this floor (in L2, they add). \
         The floor's L1 is {:.1}% of the best method's L1.",
        e.reference_spp,
        100.0 * floor.l1 / best
    )?;
    Ok(())
}

/// Which of the paper's claims hold on this evaluation.
fn claims(md: &mut String, e: &Evaluation) -> Result<()> {
    writeln!(
        md,
        "## The paper's claims, here\n\nEach judged on the per-view differences over the {} test \
         views: ✅ at least two standard errors in its favour, ❌ two against, ≈ not resolved by \
         these views (more held-out lightings would decide).\n",
        e.test_views
    )?;
    for c in e.checks() {
        writeln!(md, "- {} {}", c.verdict.mark(), c.text)?;
    }
    Ok(())
}

/// Per-stage timings (the paper's Tables 3 and 4).
fn timings(md: &mut String, e: &Evaluation) -> Result<()> {
    writeln!(
        md,
        "\n## Timings at {0}×{0} (the paper's Tables 3 and 4)\n",
        e.timing_res
    )?;
    writeln!(
        md,
        "Median of three runs on this machine's CPU (the paper: an RTX 3090). GFLOP/s: the \
         dense layers' achieved rate, beside the f32 peak of {:.0} GFLOP/s measured on the same \
         threads (FMA chains in registers).\n\n| stage | ms | GFLOP/s |\n|---|---|---|",
        e.peak_gflops
    )?;
    for t in &e.timings {
        let gflops = t.gflops.map_or(String::new(), |g| {
            format!("{g:.0} ({:.0}% of peak)", 100.0 * g / e.peak_gflops)
        });
        writeln!(md, "| {} | {:.1} | {gflops} |", t.what, t.ms)?;
    }
    Ok(())
}

/// Correlations of the error with directness and specularity, and the binned plots.
fn error_analysis(md: &mut String, e: &Evaluation, dir: &Path) -> Result<()> {
    writeln!(md, "\n## Error analysis\n")?;
    writeln!(md, "Pearson correlation, over foreground pixels of all test views, of the per-pixel L1 error with the \
        directness (share of direct light in the reference) and with the specularity (|ks| / (|kd| + |ks|)).\n")?;
    writeln!(
        md,
        "| method | corr(error, directness) | corr(error, specularity) |\n|---|---|---|"
    )?;
    for m in &e.methods {
        writeln!(
            md,
            "| {} | {:.3} | {:.3} |",
            m.name, m.corr_directness, m.corr_specularity
        )?;
    }
    for (file, title, x, pick) in [
        (
            "error-vs-directness",
            "mean L1 error against directness",
            "share of direct light",
            0,
        ),
        (
            "error-vs-specularity",
            "mean L1 error against specularity",
            "specularity",
            1,
        ),
    ] {
        let series: Vec<(String, Vec<(f64, f64)>)> = e
            .methods
            .iter()
            .map(|m| {
                let v = if pick == 0 {
                    &m.error_by_directness
                } else {
                    &m.error_by_specularity
                };
                (
                    m.name.clone(),
                    v.iter()
                        .enumerate()
                        .map(|(k, &y)| ((k as f64 + 0.5) / BINS as f64, y))
                        .collect(),
                )
            })
            .collect();
        let rel = format!("images/{file}.png");
        plot_lines(&dir.join(&rel), title, (x, "mean L1 error"), &series)?;
        writeln!(md, "\n![{title}]({rel})")?;
    }
    Ok(())
}

/// The report folder's path (relative to it) of `method`'s crop of shown test view `view`: the
/// same pixels for every method of that view.
pub fn crop_image(view: usize, method: &str) -> String {
    format!("images/{}-crop.png", view_stem(view, method))
}

/// The file stem of `method`'s images of shown test view `view`.
fn view_stem(view: usize, method: &str) -> String {
    format!("view{view}-{}", slug(method))
}

/// Frames, crops and heat maps of the shown views.
fn images(md: &mut String, e: &Evaluation, dir: &Path) -> Result<()> {
    writeln!(md, "\n## Images\n\nPer view: full frames, a {ZOOM}× crop where the first network errs most, and relative-error heat maps \
        (|error| / (reference + {RELATIVE_EPS}), black 0 → pale yellow ≥ {HEAT_MAX}). Exposure set per view from the reference; \
        every method's background (where no surface is hit, which no metric scores) is the reference's.\n")?;
    for v in &e.shown {
        let exposure = auto_exposure(&v.reference, &v.mask);
        let first = v
            .methods
            .first()
            .map(|m| m.1.as_slice())
            .unwrap_or(&v.reference);
        let window = crop_window(first, v);
        let all = std::iter::once(("reference".to_string(), &v.reference))
            .chain(v.methods.iter().map(|(n, r)| (n.clone(), r)));
        writeln!(md, "### Test view {}\n", v.index)?;
        writeln!(md, "| method | frame | crop | error |\n|---|---|---|---|")?;
        for (name, rgb) in all {
            let stem = view_stem(v.index, &name);
            let rgb = &with_background(rgb, v);
            let full = save(dir, &stem, rgb, v.width, v.height, exposure)?;
            let side = window.2 * ZOOM;
            let cr = save(
                dir,
                &format!("{stem}-crop"),
                &crop(rgb, v.width, window),
                side,
                side,
                exposure,
            )?;
            let err = if name == "reference" {
                String::new()
            } else {
                let f = save(
                    dir,
                    &format!("{stem}-error"),
                    &heat_map(rgb, v),
                    v.width,
                    v.height,
                    0.0,
                )?;
                format!("![]({f})")
            };
            writeln!(md, "| {name} | ![]({full}) | ![]({cr}) | {err} |")?;
        }
        writeln!(md)?;
    }
    Ok(())
}

/// Where the report plots its networks' validation curves (relative to its folder).
pub const VALIDATION_PLOT: &str = "images/validation-vs-seconds.png";

/// Plots the validation loss against training seconds of those `methods` that have a curve
/// (networks), one line each, into `path`; whether there was any.
pub fn plot_validation(methods: &[MethodResult], path: &Path, title: &str) -> Result<bool> {
    let series: Vec<(String, Vec<(f64, f64)>)> = methods
        .iter()
        .filter(|m| !m.validation.is_empty())
        .map(|m| (m.name.clone(), m.validation.clone()))
        .collect();
    if series.is_empty() {
        return Ok(false);
    }
    plot_lines(
        path,
        title,
        ("seconds of training", "validation log-L1"),
        &series,
    )?;
    Ok(true)
}

/// The networks' validation loss against training time on one plot (recipes and designs
/// compared at equal wall time), then each network's own loss curves.
fn training_curves(md: &mut String, e: &Evaluation, dir: &Path) -> Result<()> {
    writeln!(md, "## Training curves\n")?;
    let title = "validation loss (held-out lighting) against training time";
    if plot_validation(&e.methods, &dir.join(VALIDATION_PLOT), title)? {
        writeln!(
            md,
            "![validation loss against training time]({VALIDATION_PLOT})\n"
        )?;
    }
    for m in e.methods.iter().filter(|m| m.loss_png.is_some()) {
        let rel = format!("images/loss-{}.png", slug(&m.name));
        std::fs::copy(m.loss_png.as_ref().unwrap(), dir.join(&rel))
            .with_context(|| format!("cannot copy the training curve of {}", m.name))?;
        writeln!(md, "![{}]({rel})\n", m.name)?;
    }
    Ok(())
}
