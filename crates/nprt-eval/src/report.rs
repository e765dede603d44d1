//! The evaluation as a report folder: report.md (images beside it), report.html (the same,
//! self-contained with embedded images) and results.json.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use base64::Engine;
use glam::Vec3;
use nprt_io::{write_atomically, write_file};
use nprt_net::curves::plot_lines;
use nprt_render::video::to_image;
use nprt_scene::{luminance, srgb_to_linear};

use crate::evaluate::{Evaluation, ShownView};
use crate::method::BINS;
use crate::metrics::{Metrics, RELATIVE_EPS};

/// Relative error at which the heat map saturates.
const HEAT_MAX: f32 = 0.5;
/// Magnification of crops.
const ZOOM: usize = 3;

/// Exposure (stops) putting the 90th percentile of the foreground's luminance at 0.7.
fn auto_exposure(v: &ShownView) -> f32 {
    let mut l: Vec<f32> = (0..v.mask.len())
        .filter(|&i| v.mask[i] > 0.5)
        .map(|i| luminance(v.reference[i]))
        .collect();
    if l.is_empty() {
        return 0.0;
    }
    l.sort_by(f32::total_cmp);
    (0.7 / l[l.len() * 9 / 10].max(1e-6)).log2()
}

/// Black → purple → orange → pale yellow.
fn heat(t: f32) -> Vec3 {
    const STOPS: [Vec3; 4] = [
        Vec3::new(0.0, 0.0, 0.02),
        Vec3::new(0.45, 0.07, 0.5),
        Vec3::new(0.95, 0.45, 0.1),
        Vec3::new(1.0, 1.0, 0.75),
    ];
    let x = t.clamp(0.0, 1.0) * 3.0;
    let i = (x as usize).min(2);
    STOPS[i].lerp(STOPS[i + 1], x - i as f32)
}

/// Per-pixel relative L1 error as colours (linear values that encode to the colour map).
fn heat_map(pred: &[Vec3], v: &ShownView) -> Vec<Vec3> {
    (0..v.mask.len())
        .map(|i| {
            if v.mask[i] <= 0.5 {
                return Vec3::splat(0.5);
            }
            let r = v.reference[i];
            let e = (pred[i] - r).abs().element_sum() / (r.element_sum() + 3.0 * RELATIVE_EPS);
            // The PNG writer sRGB-encodes; decode so the colour map is what shows.
            heat(e / HEAT_MAX).map(srgb_to_linear)
        })
        .collect()
}

/// The square window (x0, y0, side) around the largest error of `pred`, smoothed over the
/// window.
fn crop_window(pred: &[Vec3], v: &ShownView) -> (usize, usize, usize) {
    let side = (v.width.min(v.height) / 3)
        .max(8)
        .min(v.width.min(v.height));
    let err: Vec<f32> = (0..v.mask.len())
        .map(|i| {
            if v.mask[i] > 0.5 {
                (pred[i] - v.reference[i]).abs().element_sum()
            } else {
                0.0
            }
        })
        .collect();
    let mut best = (0.0, 0, 0);
    let step = (side / 4).max(1);
    for y0 in (0..=v.height - side).step_by(step) {
        for x0 in (0..=v.width - side).step_by(step) {
            let s: f32 = (y0..y0 + side)
                .flat_map(|y| (x0..x0 + side).map(move |x| (x, y)))
                .map(|(x, y)| err[y * v.width + x])
                .sum();
            if s > best.0 {
                best = (s, x0, y0);
            }
        }
    }
    (best.1, best.2, side)
}

fn crop(img: &[Vec3], width: usize, (x0, y0, side): (usize, usize, usize)) -> Vec<Vec3> {
    let n = side * ZOOM;
    (0..n * n)
        .map(|i| img[(y0 + (i / n) / ZOOM) * width + x0 + (i % n) / ZOOM])
        .collect()
}

fn save(dir: &Path, name: &str, rgb: &[Vec3], w: usize, h: usize, exposure: f32) -> Result<String> {
    let file = format!("images/{name}.png");
    let img = to_image(rgb, w, h, exposure);
    let path = dir.join(&file);
    write_atomically(&path, |tmp| {
        Ok(img.save_with_format(tmp, image::ImageFormat::Png)?)
    })?;
    Ok(file)
}

/// A method name as a file-name part.
fn slug(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect()
}

fn fmt(v: f64) -> String {
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
    images(&mut md, e, dir)?;
    training_curves(&mut md, e, dir)?;
    let md_path = dir.join("report.md");
    write_file(&md_path, &md)?;
    let html_path = dir.join("report.html");
    let html = to_html(&md, dir)?;
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

/// Frames, crops and heat maps of the shown views.
fn images(md: &mut String, e: &Evaluation, dir: &Path) -> Result<()> {
    writeln!(md, "\n## Images\n\nPer view: full frames, a {ZOOM}× crop where the first network errs most, and relative-error heat maps \
        (|error| / (reference + {RELATIVE_EPS}), black 0 → pale yellow ≥ {HEAT_MAX}). Exposure set per view from the reference.\n")?;
    for v in &e.shown {
        let exposure = auto_exposure(v);
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
            let stem = format!("view{}-{}", v.index, slug(&name));
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

/// The networks' validation loss against training time on one plot (recipes and designs
/// compared at equal wall time), then each network's own loss curves.
fn training_curves(md: &mut String, e: &Evaluation, dir: &Path) -> Result<()> {
    writeln!(md, "## Training curves\n")?;
    let series: Vec<(String, Vec<(f64, f64)>)> = e
        .methods
        .iter()
        .filter(|m| !m.validation.is_empty())
        .map(|m| (m.name.clone(), m.validation.clone()))
        .collect();
    if !series.is_empty() {
        let rel = "images/validation-vs-seconds.png";
        plot_lines(
            &dir.join(rel),
            "validation loss (held-out lighting) against training time",
            ("seconds of training", "validation log-L1"),
            &series,
        )?;
        writeln!(md, "![validation loss against training time]({rel})\n")?;
    }
    for m in e.methods.iter().filter(|m| m.loss_png.is_some()) {
        let rel = format!("images/loss-{}.png", slug(&m.name));
        std::fs::copy(m.loss_png.as_ref().unwrap(), dir.join(&rel))
            .with_context(|| format!("cannot copy the training curve of {}", m.name))?;
        writeln!(md, "![{}]({rel})\n", m.name)?;
    }
    Ok(())
}

/// Renders the report's Markdown as one HTML page (pulldown-cmark, with tables) with every
/// image embedded as a data URI, so the page can be mailed or moved alone.
fn to_html(md: &str, dir: &Path) -> Result<String> {
    use pulldown_cmark::{Event, Options, Parser, Tag};
    let mut events = Vec::new();
    for event in Parser::new_ext(md, Options::ENABLE_TABLES) {
        events.push(match event {
            Event::Start(Tag::Image {
                link_type,
                dest_url,
                title,
                id,
            }) => {
                let file = dir.join(dest_url.as_ref());
                let bytes = std::fs::read(&file)
                    .with_context(|| format!("cannot read report image '{}'", file.display()))?;
                let b64 = base64::engine::general_purpose::STANDARD.encode(bytes);
                Event::Start(Tag::Image {
                    link_type,
                    dest_url: format!("data:image/png;base64,{b64}").into(),
                    title,
                    id,
                })
            }
            other => other,
        });
    }
    let mut html = String::from(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>nprt evaluation</title><style>\
         body{font-family:sans-serif;max-width:1400px;margin:2em auto;padding:0 1em}\
         table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:4px 8px;text-align:right}\
         td:first-child,th:first-child{text-align:left}img{image-rendering:pixelated;max-width:100%}\
         td img{width:192px}</style></head><body>\n",
    );
    pulldown_cmark::html::push_html(&mut html, events.into_iter());
    html += "</body></html>\n";
    Ok(html)
}
