//! The report's temporal section: each method's temporal error along the camera path beside its
//! error per frame, that error plotted against the frame (a method that lags spikes where the
//! lighting changes), and strips of consecutive frames with their temporal differences.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;
use glam::Vec3;
use nprt_io::{plot_lines, srgb_to_linear};

use super::pictures::{auto_exposure, heat, save, HEAT_MAX};
use super::{fmt, slug};
use crate::evaluate::Evaluation;
use crate::metrics::RELATIVE_EPS;
use crate::temporal::Temporal;

/// Side, in pixels, below which a strip's frames are magnified.
const STRIP_SIDE: usize = 128;

pub(super) fn temporal(md: &mut String, e: &Evaluation, dir: &Path) -> Result<()> {
    writeln!(md, "\n## Temporal stability along a camera path\n")?;
    let Some(t) = &e.temporal else {
        writeln!(md, "{}", e.temporal_note)?;
        return Ok(());
    };
    let [w, h] = t.resolution;
    writeln!(
        md,
        "{} frames at {w}×{h} along a slow move through the dataset's camera volume, lit by `{}` \
         turning, then from frame {} by `{}`; references at {} spp. The temporal error is the mean, \
         over consecutive frame pairs, foreground pixels and channels, of |(M_t − M_t−1) − \
         (R_t − R_t−1)| on linear radiance: how much a method's frames change beyond what the \
         reference's change explains (0 for the reference itself). The references' own, their \
         first halves of samples against the whole: {}. SH PRT precomputes its transport per \
         view and is not run along a path. The Neural Radiance Cache (NRC: read where a path's \
         footprint has spread; NRC-CACHE: read at the first vertex) trains online along the \
         path from a cold start, and also after {} frames at the first frame (warmed); its \
         time per frame includes its training.\n",
        t.frames,
        t.maps[0],
        t.change_at,
        t.maps[1],
        t.reference_spp,
        fmt(t.noise_floor),
        t.nrc_warmup
    )?;
    if let Some(n) = &t.nrc {
        let budget = match n.budget_ms {
            Some(b) => format!("held to the D/S frame's {b:.1} ms"),
            None => "given no network to be held to".into(),
        };
        writeln!(
            md,
            "The radiance caches, {budget}: a frame's rendering ({} path per pixel, its cache \
             reads included) measured {:.1} ms and a training step ({} pairs) {:.1} ms, so they \
             train {} step(s) per frame, a {:.0}% share of the pixels tracing a training path.\n",
            n.settings.spp,
            n.render_ms,
            n.settings.batch,
            n.step_ms,
            n.settings.steps,
            100.0 * n.settings.train_share
        )?;
    }
    method_table(md, t)?;
    l1_plot(md, t, dir)?;
    writeln!(
        md,
        "Table 6's metrics along the path (× 10³, ± the standard error over the {} frames; \
         consecutive frames are alike, so this spread understates the uncertainty):\n",
        t.frames
    )?;
    super::table6::table6(
        md,
        t.methods
            .iter()
            .map(|m| (m.name.as_str(), m.per_frame.as_slice())),
    )?;
    strips(md, t, dir)
}

/// Per method, its temporal error beside its L1 error per frame: the mean, and on the frames
/// before and at the lighting change.
fn method_table(md: &mut String, t: &Temporal) -> Result<()> {
    let c = t.change_at;
    writeln!(
        md,
        "| method | temporal error | mean L1 per frame | L1 at frame {} | L1 at frame {c} (new map) | ms per frame |\n|---|---|---|---|---|---|",
        c.saturating_sub(1)
    )?;
    for m in &t.methods {
        let l1 = &m.per_frame_l1();
        let mean = l1.iter().sum::<f64>() / l1.len().max(1) as f64;
        let at = |i: usize| l1.get(i).copied().unwrap_or(f64::NAN);
        writeln!(
            md,
            "| {} | {} | {} | {} | {} | {:.1} |",
            m.name,
            fmt(m.temporal_error),
            fmt(mean),
            fmt(at(c.saturating_sub(1))),
            fmt(at(c)),
            m.ms_per_frame
        )?;
    }
    Ok(())
}

/// The L1 error per frame of every method, plotted into the report's images.
fn l1_plot(md: &mut String, t: &Temporal, dir: &Path) -> Result<()> {
    let series: Vec<(String, Vec<(f64, f64)>)> = (t.methods.iter())
        .map(|m| {
            let points = m.per_frame_l1().into_iter().enumerate();
            (m.name.clone(), points.map(|(i, v)| (i as f64, v)).collect())
        })
        .collect();
    let rel = "images/temporal-l1.png";
    plot_lines(
        &dir.join(rel),
        "L1 error per frame along the camera path",
        ("frame", "L1 error"),
        &series,
    )?;
    writeln!(md, "\n![L1 error per frame]({rel})\n")?;
    Ok(())
}

/// Per method, the frames around the lighting change side by side, and under them each pair's
/// temporal difference |ΔM − ΔR| relative to the reference (black 0 → pale yellow ≥ HEAT_MAX).
fn strips(md: &mut String, t: &Temporal, dir: &Path) -> Result<()> {
    let Some((_, reference)) = t.strips.first() else {
        return Ok(());
    };
    let [w, h] = t.resolution.map(|v| v as usize);
    let first = t.strip_first();
    let masks = &t.strip_masks;
    let exposure = auto_exposure(&reference.concat(), &masks.concat());
    // Small frames are magnified to at least STRIP_SIDE pixels a side, pixel for pixel.
    let zoom = STRIP_SIDE.div_ceil(w.max(1)).max(1);
    let strip = |frames: &[Vec<Vec3>]| side_by_side(frames, w, h, zoom);
    let (sw, sh) = (w * zoom, h * zoom);
    writeln!(
        md,
        "### Frames {first} to {} (the lighting changes at frame {})\n\nEach method's frames, and \
         under them each pair's temporal difference relative to the reference's value (black 0 → \
         pale yellow ≥ {HEAT_MAX}).\n\n| method | frames | temporal differences |\n|---|---|---|",
        first + reference.len() - 1,
        t.change_at
    )?;
    for (name, frames) in &t.strips {
        let stem = format!("temporal-{}", slug(name));
        let row = save(dir, &stem, &strip(frames), sw * frames.len(), sh, exposure)?;
        let diff = match name.as_str() {
            "reference" => String::new(),
            _ => {
                let pairs: Vec<Vec<Vec3>> = (1..frames.len())
                    .map(|k| difference(frames, reference, masks, k))
                    .collect();
                let n = pairs.len();
                let f = save(
                    dir,
                    &format!("{stem}-diff"),
                    &strip(&pairs),
                    sw * n,
                    sh,
                    0.0,
                )?;
                format!("![]({f})")
            }
        };
        writeln!(md, "| {name} | ![]({row}) | {diff} |")?;
    }
    Ok(())
}

/// Frames of `w` × `h` placed left to right, each pixel repeated `zoom` × `zoom` times.
fn side_by_side(frames: &[Vec<Vec3>], w: usize, h: usize, zoom: usize) -> Vec<Vec3> {
    let (n, zw) = (frames.len(), w * zoom);
    (0..n * zw * h * zoom)
        .map(|i| {
            let (y, x) = (i / (n * zw) / zoom, i % (n * zw));
            frames[x / zw][y * w + x % zw / zoom]
        })
        .collect()
}

/// The relative temporal difference of pair (k − 1, k) as colours; grey outside the foreground
/// of both frames.
fn difference(m: &[Vec<Vec3>], r: &[Vec<Vec3>], masks: &[Vec<f32>], k: usize) -> Vec<Vec3> {
    (0..m[k].len())
        .map(|i| {
            if masks[k - 1][i] <= 0.5 || masks[k][i] <= 0.5 {
                return Vec3::splat(0.5);
            }
            let d = ((m[k][i] - m[k - 1][i]) - (r[k][i] - r[k - 1][i])).abs();
            let e = d.element_sum() / (r[k][i].element_sum() + 3.0 * RELATIVE_EPS);
            // The PNG writer sRGB-encodes; decode so the colour map is what shows.
            heat(e / HEAT_MAX).map(srgb_to_linear)
        })
        .collect()
}
