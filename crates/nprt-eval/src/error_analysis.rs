//! Per-method error bookkeeping over the test views: metrics per view, and each foreground
//! pixel's error against its share of direct light and its specularity (the paper's error
//! analysis), binned and correlated.

use glam::{DVec3, Vec3};
use nprt_data::views::ImageView;
use nprt_scene::luminance;

use crate::method::{Family, MethodResult, BINS};
use crate::metrics::{correlation, Metrics};

/// Accumulates one method's per-view metrics and per-pixel error statistics.
pub struct Accumulator {
    pub result: MethodResult,
    err: Vec<f64>,
    direct: Vec<f64>,
    spec: Vec<f64>,
    ms: Vec<f64>,
    /// Foreground sums of prediction and reference, per channel.
    sums: [DVec3; 2],
    /// Each view's tint error.
    tints: Vec<f64>,
}

impl Accumulator {
    pub fn new(name: &str, family: Family, params: Option<usize>) -> Self {
        Accumulator {
            result: MethodResult::new(name, family, params),
            err: vec![],
            direct: vec![],
            spec: vec![],
            ms: vec![],
            sums: [DVec3::ZERO; 2],
            tints: vec![],
        }
    }

    pub fn add(&mut self, view: &ImageView, pred: &[Vec3], ms: f64) {
        let g = &view.gbuffer;
        self.result
            .per_view
            .push(Metrics::compute(pred, &view.radiance, &g.mask, view.width));
        self.ms.push(ms);
        let sums = [light(pred, &g.mask), light(&view.radiance, &g.mask)];
        for i in (0..g.mask.len()).filter(|&i| g.mask[i] > 0.5) {
            let r = view.radiance[i];
            self.err
                .push(((pred[i] - r).abs().element_sum() / 3.0) as f64);
            self.direct
                .push((luminance(view.direct[i]) / luminance(r).max(1e-6)).clamp(0.0, 1.0) as f64);
            let (kd, ks) = (g.kd[i].element_sum(), g.ks[i].element_sum());
            self.spec.push((ks / (kd + ks).max(1e-6)) as f64);
        }
        self.sums[0] += sums[0];
        self.sums[1] += sums[1];
        self.tints.push(tint_error(sums[0] / sums[1]));
    }

    pub fn finish(mut self) -> MethodResult {
        let r = &mut self.result;
        r.mean = Metrics::mean(&r.per_view);
        r.ms_per_view = self.ms.iter().sum::<f64>() / self.ms.len().max(1) as f64;
        r.corr_directness = correlation(&self.err, &self.direct);
        r.corr_specularity = correlation(&self.err, &self.spec);
        r.error_by_directness = binned(&self.direct, &self.err);
        r.error_by_specularity = binned(&self.spec, &self.err);
        r.level = (self.sums[0] / self.sums[1]).to_array();
        r.tint_error = self.tints.iter().sum::<f64>() / self.tints.len().max(1) as f64;
        self.result
    }
}

/// The light an image shows on the foreground, per channel: negative values (SH PRT's ringing)
/// count as none, as on a display. Summed as they were, an SH frame whose light summed to about
/// zero gave a tint error of order 1e10; with the levels non-negative it is at most 2.
pub(crate) fn light(rgb: &[Vec3], mask: &[f32]) -> DVec3 {
    rgb.iter()
        .zip(mask)
        .filter(|(_, &m)| m > 0.5)
        .map(|(c, _)| c.max(Vec3::ZERO).as_dvec3())
        .sum()
}

/// The largest relative deviation of a channel's level from the mean of the three.
fn tint_error(level: DVec3) -> f64 {
    let mean = level.element_sum() / 3.0;
    (level - DVec3::splat(mean)).abs().max_element() / mean.max(1e-12)
}

/// Mean of `y` in `BINS` equal bins of `x` ∈ [0, 1] (NaN where a bin is empty).
fn binned(x: &[f64], y: &[f64]) -> Vec<f64> {
    let mut sum = [0.0; BINS];
    let mut n = vec![0usize; BINS];
    for (a, b) in x.iter().zip(y) {
        let k = ((a * BINS as f64) as usize).min(BINS - 1);
        sum[k] += b;
        n[k] += 1;
    }
    sum.iter()
        .zip(&n)
        .map(|(s, &c)| if c > 0 { s / c as f64 } else { f64::NAN })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tint_error_ignores_brightness_and_measures_colour_balance() {
        assert!(tint_error(DVec3::splat(0.7)) < 1e-12);
        assert!(tint_error(DVec3::splat(1.3)) < 1e-12);
        // A warm map rendered neutral: red 20% under the mean, blue 20% over it.
        assert!((tint_error(DVec3::new(0.8, 1.0, 1.2)) - 0.2).abs() < 1e-12);
        assert!((tint_error(DVec3::new(0.4, 0.5, 0.6)) - 0.2).abs() < 1e-12);
    }

    #[test]
    fn negative_light_counts_as_none_so_the_tint_error_stays_bounded() {
        let mask = [1.0, 1.0, 0.0];
        // The second pixel rings below zero in green and blue; the third is background.
        let rgb = [
            Vec3::new(0.5, 0.2, 0.1),
            Vec3::new(0.1, -0.2, -0.1),
            Vec3::splat(9.0),
        ];
        let l = light(&rgb, &mask);
        assert!((l - DVec3::new(0.6, 0.2, 0.1)).abs().max_element() < 1e-6);
        // Light in one channel only: the largest tint error there is.
        assert!((tint_error(DVec3::new(3.0, 0.0, 0.0)) - 2.0).abs() < 1e-12);
        let dark = light(&[Vec3::splat(-1.0)], &[1.0]);
        assert!(tint_error(dark) < 1e-12);
    }
}
