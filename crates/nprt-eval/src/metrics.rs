//! Image error metrics of the paper's Tables 5 and 6, on linear radiance over foreground
//! pixels (docs/evaluation.md defines each).

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// ε of the relative metrics (MAPE, MRSE): keeps near-black reference pixels from dominating.
pub const RELATIVE_EPS: f32 = 0.01;

/// Errors of one prediction against its reference, each a mean over foreground pixels and the
/// three colour channels (dSSIM: over foreground window centres).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    pub l1: f64,
    pub l2: f64,
    pub rmse: f64,
    pub dssim: f64,
    pub mape: f64,
    pub mrse: f64,
    pub log_l1: f64,
}

impl Metrics {
    pub const NAMES: [&'static str; 7] = ["L1", "L2", "RMSE", "dSSIM", "MAPE", "MRSE", "log-L1"];
    /// Indices into [`Self::NAMES`] and [`Self::values`].
    pub const L1: usize = 0;
    pub const RMSE: usize = 2;
    pub const LOG_L1: usize = 6;
    /// The metrics of the paper's Table 6 (L1, L2, dSSIM, MAPE, MRSE).
    pub const TABLE6: [usize; 5] = [0, 1, 3, 4, 5];

    pub fn values(&self) -> [f64; 7] {
        [
            self.l1,
            self.l2,
            self.rmse,
            self.dssim,
            self.mape,
            self.mrse,
            self.log_l1,
        ]
    }

    /// Errors of `pred` against `reference` (row-major `width` wide) where `mask` > 0.5.
    pub fn compute(pred: &[Vec3], reference: &[Vec3], mask: &[f32], width: usize) -> Metrics {
        let (mut m, mut n) = (Metrics::default(), 0usize);
        for i in (0..mask.len()).filter(|&i| mask[i] > 0.5) {
            for c in 0..3 {
                let (p, r) = (pred[i][c] as f64, reference[i][c] as f64);
                let d = p - r;
                m.l1 += d.abs();
                m.l2 += d * d;
                m.mape += d.abs() / (r.abs() + RELATIVE_EPS as f64);
                m.mrse += d * d / (r * r + RELATIVE_EPS as f64);
                m.log_l1 += nprt_net::loss::log_l1_error(p, r);
            }
            n += 3;
        }
        if n == 0 {
            return Metrics::default();
        }
        let n = n as f64;
        for v in [
            &mut m.l1,
            &mut m.l2,
            &mut m.mape,
            &mut m.mrse,
            &mut m.log_l1,
        ] {
            *v /= n;
        }
        m.rmse = m.l2.sqrt();
        m.dssim = (1.0 - ssim(pred, reference, mask, width)) / 2.0;
        m
    }

    /// Mean of per-view metrics.
    pub fn mean(all: &[Metrics]) -> Metrics {
        let n = all.len().max(1) as f64;
        let sum = |f: fn(&Metrics) -> f64| all.iter().map(f).sum::<f64>() / n;
        Metrics {
            l1: sum(|m| m.l1),
            l2: sum(|m| m.l2),
            rmse: sum(|m| m.rmse),
            dssim: sum(|m| m.dssim),
            mape: sum(|m| m.mape),
            mrse: sum(|m| m.mrse),
            log_l1: sum(|m| m.log_l1),
        }
    }
}

/// Mean SSIM (Wang et al. 2004: 11×11 Gaussian window, σ 1.5, K1 0.01, K2 0.03, dynamic range 1)
/// per colour channel, over windows centred on foreground pixels; background pixels count as
/// black in both images so they add no difference. Hand-written: the SSIM crates work on whole
/// 8-bit images, without a foreground mask or linear HDR values.
pub fn ssim(pred: &[Vec3], reference: &[Vec3], mask: &[f32], width: usize) -> f64 {
    const R: i64 = 5;
    let (c1, c2) = (0.01f64.powi(2), 0.03f64.powi(2));
    let g: Vec<f64> = (-R..=R)
        .map(|k| (-(k * k) as f64 / (2.0 * 1.5 * 1.5)).exp())
        .collect();
    let height = mask.len() / width.max(1);
    let fg = |i: usize| mask[i] > 0.5;
    let (mut total, mut count) = (0.0, 0usize);
    for i in (0..mask.len()).filter(|&i| fg(i)) {
        let (x, y) = ((i % width) as i64, (i / width) as i64);
        for c in 0..3 {
            let (mut wsum, mut mp, mut mr, mut pp, mut rr, mut pr) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            for dy in -R..=R {
                for dx in -R..=R {
                    let (sx, sy) = (x + dx, y + dy);
                    if sx < 0 || sy < 0 || sx >= width as i64 || sy >= height as i64 {
                        continue;
                    }
                    let j = sy as usize * width + sx as usize;
                    let w = g[(dx + R) as usize] * g[(dy + R) as usize];
                    let (p, r) = if fg(j) {
                        (pred[j][c] as f64, reference[j][c] as f64)
                    } else {
                        (0.0, 0.0)
                    };
                    wsum += w;
                    mp += w * p;
                    mr += w * r;
                    pp += w * p * p;
                    rr += w * r * r;
                    pr += w * p * r;
                }
            }
            let (mp, mr) = (mp / wsum, mr / wsum);
            let vp = pp / wsum - mp * mp;
            let vr = rr / wsum - mr * mr;
            let cov = pr / wsum - mp * mr;
            total += ((2.0 * mp * mr + c1) * (2.0 * cov + c2))
                / ((mp * mp + mr * mr + c1) * (vp + vr + c2));
            count += 1;
        }
    }
    if count == 0 {
        1.0
    } else {
        total / count as f64
    }
}

/// Pearson correlation of two equally long series (0 when either is constant).
pub fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()) as f64;
    if n < 2.0 {
        return 0.0;
    }
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    if saa <= 0.0 || sbb <= 0.0 {
        0.0
    } else {
        sab / (saa * sbb).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: usize, h: usize, f: impl Fn(usize, usize) -> Vec3) -> Vec<Vec3> {
        (0..w * h).map(|i| f(i % w, i / w)).collect()
    }

    #[test]
    fn known_offsets() {
        let (w, h) = (16, 12);
        let r = image(w, h, |x, y| Vec3::splat(0.2 + 0.05 * ((x + y) % 5) as f32));
        let mut mask = vec![1.0; w * h];
        let same = Metrics::compute(&r, &r, &mask, w);
        assert_eq!(same.l1, 0.0);
        assert!(same.dssim.abs() < 1e-12, "{same:?}");
        let p: Vec<Vec3> = r.iter().map(|v| *v + 0.1).collect();
        let m = Metrics::compute(&p, &r, &mask, w);
        assert!(
            (m.l1 - 0.1).abs() < 1e-6 && (m.l2 - 0.01).abs() < 1e-6 && (m.rmse - 0.1).abs() < 1e-6
        );
        let mape: f64 = r.iter().map(|v| 0.1 / (v.x as f64 + 0.01)).sum::<f64>() / r.len() as f64;
        assert!((m.mape - mape).abs() < 1e-6, "{} vs {mape}", m.mape);
        let log: f64 = r
            .iter()
            .map(|v| ((1.1 + v.x as f64) / (1.0 + v.x as f64)).ln())
            .sum::<f64>()
            / r.len() as f64;
        assert!((m.log_l1 - log).abs() < 1e-6);
        assert!(m.dssim > 0.0);
        // Background pixels carry no error, whatever they hold.
        let mut q = r.clone();
        for i in 0..w {
            q[i] = Vec3::splat(100.0);
            mask[i] = 0.0;
        }
        let m = Metrics::compute(&q, &r, &mask, w);
        assert_eq!((m.l1, m.mrse), (0.0, 0.0));
    }

    #[test]
    fn ssim_drops_with_structure_loss() {
        let (w, h) = (24, 24);
        let r = image(w, h, |x, y| {
            Vec3::splat(((x / 3 + y / 3) % 2) as f32 * 0.8 + 0.1)
        });
        let flat = vec![Vec3::splat(0.5); w * h];
        let mask = vec![1.0; w * h];
        let s = ssim(&flat, &r, &mask, w);
        assert!(s < 0.2, "a flat image loses the checker's structure: {s}");
        assert!((correlation(&[1.0, 2.0, 3.0], &[2.0, 4.0, 6.5]) - 0.9986).abs() < 1e-3);
    }
}
