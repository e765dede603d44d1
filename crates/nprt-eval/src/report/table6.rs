//! The paper's Table 6 as it prints it: L1, L2, dSSIM, MAPE and MRSE × 10³ per method, here
//! with each mean's standard error over the views (or frames) it averages.

use std::fmt::Write as _;

use anyhow::Result;

use crate::metrics::Metrics;

/// Writes Table 6 into `md` for `rows` (a method's name and its per-view or per-frame metrics).
pub fn table6<'a>(
    md: &mut String,
    rows: impl Iterator<Item = (&'a str, &'a [Metrics])>,
) -> Result<()> {
    write!(md, "| method |")?;
    for k in Metrics::TABLE6 {
        write!(md, " {} × 10³ |", Metrics::NAMES[k])?;
    }
    writeln!(md, "\n|---|{}", "---|".repeat(Metrics::TABLE6.len()))?;
    for (name, values) in rows {
        write!(md, "| {name} |")?;
        for k in Metrics::TABLE6 {
            let text = mean_and_se_text(values.iter().map(|m| m.values()[k]), 1e3);
            write!(md, " {text} |")?;
        }
        writeln!(md)?;
    }
    writeln!(md)?;
    Ok(())
}

/// The mean of `values` times `scale` and its standard error, as reports print them (two
/// decimals): "mean ± se"; the mean alone where one value gives no spread; "–" where there is
/// no value or the mean is not finite. A report never prints NaN.
pub fn mean_and_se_text(values: impl Iterator<Item = f64>, scale: f64) -> String {
    let v: Vec<f64> = values.collect();
    let (mean, se) = mean_and_se(v.iter().copied());
    match (v.len(), mean.is_finite(), se.is_finite()) {
        (0, _, _) | (_, false, _) => "–".into(),
        (_, true, true) => format!("{:.2} ± {:.2}", scale * mean, scale * se),
        (_, true, false) => format!("{:.2}", scale * mean),
    }
}

/// The mean of `values` and its standard error (NaN with fewer than two).
pub fn mean_and_se(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let v: Vec<f64> = values.collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    if v.len() < 2 {
        return (mean, f64::NAN);
    }
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_standard_error_is_the_spread_over_root_n() {
        let (mean, se) = mean_and_se([1.0, 2.0, 3.0, 4.0].into_iter());
        assert_eq!(mean, 2.5);
        // Sample variance 5/3 over 4 values.
        assert!((se - (5.0f64 / 3.0 / 4.0).sqrt()).abs() < 1e-12);
        assert!(mean_and_se([1.0].into_iter()).1.is_nan());
        // Printed: no ± over one value, no NaN over none.
        assert_eq!(
            mean_and_se_text([1.0, 2.0].into_iter(), 1e3),
            "1500.00 ± 500.00"
        );
        assert_eq!(mean_and_se_text([0.015].into_iter(), 1e3), "15.00");
        assert_eq!(mean_and_se_text(std::iter::empty(), 1e3), "–");
        assert_eq!(mean_and_se_text([f64::NAN, 1.0].into_iter(), 1e3), "–");
    }
}
