//! Line plots as PNG (loss curves, error against budget), drawn with an embedded font so
//! that they look the same on machines without system fonts.

use std::ops::Range;
use std::path::Path;
use std::sync::Once;

use anyhow::{anyhow, Result};
use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::atomic::write_atomically;

fn register_font() {
    static FONT: Once = Once::new();
    FONT.call_once(|| {
        // Embedded so that plots render identically on machines without system fonts.
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .ok();
    });
}

// Sixteen distinct colours: an evaluation's temporal plot has a dozen methods or more, and
// eight made two of them share one.
const PALETTE: [RGBColor; 16] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 0),
    RGBColor(255, 187, 120),
    RGBColor(152, 223, 138),
    RGBColor(174, 199, 232),
    RGBColor(255, 152, 150),
    RGBColor(197, 176, 213),
];

/// `v` to two significant digits.
fn round_to_2_digits(v: f64) -> f64 {
    let scale = 10f64.powi(1 - v.abs().log10().floor() as i32);
    (v * scale).round() / scale
}

/// The axes of `series`: x from 0 (or the least x, where negative) to the largest; y, log
/// scaled, from just below the least positive value to just above the largest; y's ticks.
fn axes(series: &[(String, Vec<(f64, f64)>)]) -> (Range<f64>, Range<f64>, Vec<f64>) {
    let values = || {
        series
            .iter()
            .flat_map(|s| s.1.iter().map(|p| p.1))
            .filter(|v| v.is_finite() && *v > 0.0)
    };
    let lo = values().fold(f64::INFINITY, f64::min);
    let hi = values().fold(0.0, f64::max);
    let (lo, hi) = if lo < hi {
        (lo * 0.9, hi * 1.1)
    } else {
        (1e-3, 1.0)
    };
    let xs = || series.iter().flat_map(|s| s.1.iter().map(|p| p.0));
    // From 0 for positive x (epochs, frames), from the least for negative x (a log of time).
    let x_min = xs().fold(0.0, f64::min);
    let x_max = xs().fold(f64::NEG_INFINITY, f64::max).max(x_min + 1e-3);
    // Ticks where the log axis's own (powers of ten) would leave a narrow range unlabelled.
    let ticks: Vec<f64> = (0..=5)
        .map(|i| round_to_2_digits(lo * (hi / lo).powf(i as f64 / 5.0)))
        .collect();
    (x_min..x_max, lo..hi, ticks)
}

/// Named series as lines with markers on a log-scaled y axis, as a PNG.
pub fn plot_lines(
    path: &Path,
    title: &str,
    (x_desc, y_desc): (&str, &str),
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<()> {
    register_font();
    let (w, h) = (800u32, 500u32);
    let mut buf = vec![0u8; (w * h * 3) as usize];
    let (x, y, ticks) = axes(series);
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let err = |e: DrawingAreaErrorKind<_>| anyhow!("cannot draw plot '{title}': {e:?}");
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(x, y.log_scale().with_key_points(ticks))
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .y_label_formatter(&|v| format!("{v:.3}"))
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(err)?;
        for (i, (name, points)) in series.iter().enumerate() {
            let colour = PALETTE[i % PALETTE.len()];
            let points: Vec<(f64, f64)> = points
                .iter()
                .copied()
                .filter(|p| p.1.is_finite() && p.1 > 0.0)
                .collect();
            chart
                .draw_series(LineSeries::new(
                    points.iter().copied(),
                    colour.stroke_width(2),
                ))
                .map_err(err)?
                .label(name.as_str())
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2))
                });
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                .map_err(err)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    write_atomically(path, |tmp| {
        image::save_buffer_with_format(
            tmp,
            &buf,
            w,
            h,
            image::ExtendedColorType::Rgb8,
            image::ImageFormat::Png,
        )?;
        Ok(())
    })
}
