//! Loss curves of a training run: a CSV table and a PNG plot.

use std::path::Path;
use std::sync::Once;

use anyhow::{anyhow, Result};
use nprt_trace::exr_io::write_atomically;
use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::train::LossRow;

/// `step,epoch,samples,seconds,train_loss,val_loss`; empty cells where a row has no value.
pub fn write_csv(path: &Path, rows: &[LossRow]) -> Result<()> {
    let cell = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.6}"));
    let mut text = String::from("step,epoch,samples,seconds,train_loss,val_loss\n");
    for r in rows {
        text += &format!(
            "{},{:.4},{},{:.2},{},{}\n",
            r.step,
            r.epoch,
            r.samples,
            r.seconds,
            cell(r.train),
            cell(r.val)
        );
    }
    write_atomically(path, |tmp| Ok(std::fs::write(tmp, text)?))
}

fn register_font() {
    static FONT: Once = Once::new();
    FONT.call_once(|| {
        // Embedded so that plots render identically on machines without system fonts.
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .ok();
    });
}

/// Training and validation loss against epochs, log-scaled.
pub fn plot(path: &Path, rows: &[LossRow], title: &str) -> Result<()> {
    register_font();
    let (w, h) = (800u32, 500u32);
    let mut buf = vec![0u8; (w * h * 3) as usize];
    let train: Vec<(f64, f64)> = rows.iter().filter_map(|r| Some((r.epoch, r.train?))).collect();
    let val: Vec<(f64, f64)> = rows.iter().filter_map(|r| Some((r.epoch, r.val?))).collect();
    let values = || train.iter().chain(&val).map(|p| p.1).filter(|v| v.is_finite() && *v > 0.0);
    let lo = values().fold(f64::INFINITY, f64::min);
    let hi = values().fold(0.0, f64::max);
    let (lo, hi) = if lo < hi { (lo * 0.9, hi * 1.1) } else { (1e-3, 1.0) };
    let x_max = rows.iter().map(|r| r.epoch).fold(1e-3, f64::max);
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let err = |e: DrawingAreaErrorKind<_>| anyhow!("cannot draw loss plot: {e:?}");
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(format!("nprt training: {title}"), ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(0f64..x_max, (lo..hi).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("epoch")
            .y_desc("log-L1 loss")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(err)?;
        let blue = RGBColor(31, 119, 180);
        let red = RGBColor(214, 39, 40);
        chart
            .draw_series(LineSeries::new(train.iter().copied(), blue.stroke_width(2)))
            .map_err(err)?
            .label("training")
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], blue.stroke_width(2)));
        chart
            .draw_series(LineSeries::new(val.iter().copied(), red.stroke_width(2)))
            .map_err(err)?
            .label("validation (held-out lighting)")
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], red.stroke_width(2)));
        chart
            .draw_series(val.iter().map(|&p| Circle::new(p, 3, red.filled())))
            .map_err(err)?;
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
        image::save_buffer_with_format(tmp, &buf, w, h, image::ExtendedColorType::Rgb8, image::ImageFormat::Png)?;
        Ok(())
    })
}
