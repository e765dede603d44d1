//! Piecewise-constant 1D and 2D distributions used to importance-sample environment maps.

/// A piecewise-constant distribution over [0, 1) with `n` equal cells.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    /// Cumulative, normalised: `cdf[0] = 0`, `cdf[n] = 1`.
    cdf: Vec<f32>,
    /// Cell weights as given (not normalised).
    func: Vec<f32>,
    /// Integral of the weights over [0,1), i.e. their mean.
    integral: f32,
}

impl Distribution1D {
    pub fn new(func: Vec<f32>) -> Self {
        let n = func.len();
        assert!(n > 0, "a distribution needs at least one cell");
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0f64);
        let mut acc = 0.0f64;
        for &f in &func {
            acc += f.max(0.0) as f64 / n as f64;
            cdf.push(acc);
        }
        let integral = acc;
        let cdf = if integral > 0.0 {
            cdf.iter().map(|c| (c / integral) as f32).collect()
        } else {
            // A black row or map: fall back to uniform so sampling stays defined.
            (0..=n).map(|i| i as f32 / n as f32).collect()
        };
        Self { cdf, func, integral: integral as f32 }
    }

    pub fn len(&self) -> usize {
        self.func.len()
    }

    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// Density of the continuous sample in cell `i`.
    pub fn pdf(&self, i: usize) -> f32 {
        if self.integral > 0.0 {
            self.func[i].max(0.0) / self.integral
        } else {
            1.0
        }
    }

    /// Returns (continuous sample in [0,1), cell index, density).
    pub fn sample(&self, u: f32) -> (f32, usize, f32) {
        let n = self.func.len();
        // Last cell whose cdf start is <= u.
        let i = self.cdf.partition_point(|&c| c <= u).saturating_sub(1).min(n - 1);
        let width = self.cdf[i + 1] - self.cdf[i];
        let du = if width > 0.0 { ((u - self.cdf[i]) / width).clamp(0.0, 1.0) } else { 0.5 };
        let x = ((i as f32 + du) / n as f32).min(1.0 - f32::EPSILON);
        (x, i, self.pdf(i))
    }
}

/// A piecewise-constant 2D distribution over [0,1)²: a marginal over rows and one conditional
/// per row.
#[derive(Clone, Debug)]
pub struct Distribution2D {
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// `func` is row-major with `width` cells per row.
    pub fn new(func: &[f32], width: usize) -> Self {
        let rows: Vec<_> = func.chunks(width).map(|r| Distribution1D::new(r.to_vec())).collect();
        let marginal = Distribution1D::new(rows.iter().map(|r| r.integral()).collect());
        Self { rows, marginal }
    }

    /// Returns ((u, v), density over the unit square).
    pub fn sample(&self, u: glam::Vec2) -> (glam::Vec2, f32) {
        let (v, row, pdf_v) = self.marginal.sample(u.y);
        let (x, _, pdf_u) = self.rows[row].sample(u.x);
        (glam::vec2(x, v), pdf_u * pdf_v)
    }

    pub fn pdf(&self, p: glam::Vec2) -> f32 {
        let h = self.marginal.len();
        let row = ((p.y * h as f32) as usize).min(h - 1);
        let w = self.rows[row].len();
        let col = ((p.x * w as f32) as usize).min(w - 1);
        self.marginal.pdf(row) * self.rows[row].pdf(col)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampling_follows_weights() {
        let d = Distribution1D::new(vec![1.0, 0.0, 3.0]);
        let n = 30000;
        let mut counts = [0usize; 3];
        for k in 0..n {
            let (_, i, _) = d.sample((k as f32 + 0.5) / n as f32);
            counts[i] += 1;
        }
        assert_eq!(counts[1], 0);
        assert!((counts[0] as f32 / n as f32 - 0.25).abs() < 1e-3, "{counts:?}");
        assert!((d.pdf(2) - 2.25).abs() < 1e-6);
    }

    #[test]
    fn density_integrates_to_one() {
        let f: Vec<f32> = (0..64).map(|i| ((i * 7) % 11) as f32).collect();
        let d = Distribution2D::new(&f, 8);
        let mut total = 0.0;
        for y in 0..8 {
            for x in 0..8 {
                total += d.pdf(glam::vec2((x as f32 + 0.5) / 8.0, (y as f32 + 0.5) / 8.0)) / 64.0;
            }
        }
        assert!((total - 1.0).abs() < 1e-5, "{total}");
        let (p, pdf) = d.sample(glam::vec2(0.3, 0.7));
        assert!((d.pdf(p) - pdf).abs() < 1e-4 * pdf.max(1.0));
    }
}
