//! A power law y = a·t^b fitted to measurements by least squares on their logarithms: how
//! `nprt paper --snapshots` extends a design's RMSE against training time past the last point,
//! said as a projection with its fit.

/// y = scale · t^exponent, and how well it fits (R² of the logarithms).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PowerLaw {
    pub scale: f64,
    pub exponent: f64,
    pub r2: f64,
}

impl PowerLaw {
    /// The fit to `(t, y)` points with t and y positive and finite (the others left out); None
    /// below three such points or where every t is the same.
    pub fn fit(points: &[(f64, f64)]) -> Option<PowerLaw> {
        let logs: Vec<(f64, f64)> = (points.iter())
            .filter(|(t, y)| t.is_finite() && y.is_finite() && *t > 0.0 && *y > 0.0)
            .map(|(t, y)| (t.ln(), y.ln()))
            .collect();
        if logs.len() < 3 {
            return None;
        }
        let n = logs.len() as f64;
        let (mx, my) = logs
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
        let sxx: f64 = logs.iter().map(|(x, _)| (x - mx).powi(2)).sum();
        let sxy: f64 = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
        let syy: f64 = logs.iter().map(|(_, y)| (y - my).powi(2)).sum();
        if sxx <= 0.0 {
            return None;
        }
        let exponent = sxy / sxx;
        let r2 = match syy > 0.0 {
            true => sxy * sxy / (sxx * syy),
            false => 1.0,
        };
        Some(PowerLaw {
            scale: (my - exponent * mx).exp(),
            exponent,
            r2,
        })
    }

    pub fn at(&self, t: f64) -> f64 {
        self.scale * t.powf(self.exponent)
    }

    /// The t at which the law reaches `y`; None where it never does (a law that does not fall
    /// toward a lower `y`, or rise toward a higher one).
    pub fn reaches(&self, y: f64) -> Option<f64> {
        let t = ((y / self.scale).ln() / self.exponent).exp();
        (self.exponent != 0.0 && y > 0.0 && t.is_finite()).then_some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_power_law_is_recovered_and_projected() {
        let points: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0, 16.0]
            .map(|t: f64| (t, 0.08 * t.powf(-0.25)))
            .to_vec();
        let fit = PowerLaw::fit(&points).unwrap();
        assert!((fit.scale - 0.08).abs() < 1e-12, "{fit:?}");
        assert!((fit.exponent + 0.25).abs() < 1e-12, "{fit:?}");
        assert!((fit.r2 - 1.0).abs() < 1e-12, "{fit:?}");
        // 0.08 · t^−0.25 = 0.02 at t = 4⁴ = 256.
        assert!((fit.reaches(0.02).unwrap() - 256.0).abs() < 1e-9);
        assert!((fit.at(256.0) - 0.02).abs() < 1e-15);
        // A flat law never gets anywhere; too few usable points fit nothing.
        let flat = PowerLaw::fit(&[(1.0, 0.1), (2.0, 0.1), (4.0, 0.1)]).unwrap();
        assert_eq!(flat.reaches(0.05), None);
        assert_eq!(PowerLaw::fit(&[(1.0, 0.1), (2.0, 0.09), (0.0, 0.08)]), None);
        assert_eq!(PowerLaw::fit(&[(2.0, 0.1), (2.0, 0.09), (2.0, 0.08)]), None);
    }

    #[test]
    fn noise_lowers_the_fits_r2() {
        let points = [(1.0, 0.1), (2.0, 0.07), (4.0, 0.09), (8.0, 0.05)];
        let fit = PowerLaw::fit(&points).unwrap();
        assert!(
            fit.exponent < 0.0 && fit.r2 < 0.9 && fit.r2 > 0.0,
            "{fit:?}"
        );
    }
}
