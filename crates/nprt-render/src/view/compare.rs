//! The viewer's comparison with path tracing (the V key): the network's frame left of a
//! divider and the progressive path-traced reference of the same view and lighting right of
//! it, or the per-pixel error between the two in false colour; and the frame's L1 against the
//! reference, which the overlay prints.

use glam::Vec3;

/// What the window shows of the comparison.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Compare {
    /// The network's frame alone.
    #[default]
    Off,
    /// The network's frame left of the divider, the reference right of it.
    Split,
    /// The relative L1 of each pixel in false colour (once the reference has [`ERROR_SPP`]).
    Error,
}

/// Reference samples per pixel before the error is shown: fewer, and the reference's own
/// noise is most of what the false colour would show.
pub const ERROR_SPP: u32 = 16;

/// The radiance added to a reference pixel's in the relative L1's denominator, so that black
/// pixels do not dominate it.
const EPSILON: f32 = 0.01;

/// sRGB stops of the false colour, from no error to [`ERROR_SCALE`] and above.
const RAMP: [[f32; 3]; 5] = [
    [0.0, 0.0, 0.25],
    [0.0, 0.45, 1.0],
    [0.1, 0.9, 0.3],
    [1.0, 0.9, 0.0],
    [1.0, 0.0, 0.0],
];

/// The relative L1 shown at the ramp's top (and above).
pub const ERROR_SCALE: f32 = 1.0;

impl Compare {
    /// The next mode, as V steps through them.
    pub fn next(self) -> Self {
        match self {
            Compare::Off => Compare::Split,
            Compare::Split => Compare::Error,
            Compare::Error => Compare::Off,
        }
    }
}

/// A pixel's relative L1 error: the channels' absolute differences over the reference's.
pub fn relative_l1(model: Vec3, reference: Vec3) -> f32 {
    (model - reference).abs().element_sum() / (reference.element_sum() + 3.0 * EPSILON)
}

/// The mean absolute difference of the two frames over pixels and channels (the L1 of
/// `nprt eval`).
pub fn l1(model: &[Vec3], reference: &[Vec3]) -> f64 {
    let sum: f64 = (model.iter().zip(reference))
        .map(|(m, r)| (*m - *r).abs().element_sum() as f64)
        .sum();
    sum / (3 * model.len().max(1)) as f64
}

/// The false colour of `t` in 0..1 (sRGB, 0..1).
pub fn ramp(t: f32) -> [f32; 3] {
    let x = t.clamp(0.0, 1.0) * (RAMP.len() - 1) as f32;
    let i = (x as usize).min(RAMP.len() - 2);
    let f = x - i as f32;
    std::array::from_fn(|c| RAMP[i][c] * (1.0 - f) + RAMP[i + 1][c] * f)
}

/// Linear radiance that the presenter, at `exposure` stops, shows as the sRGB colour `c`.
fn shown_as(c: [f32; 3], exposure: f32) -> Vec3 {
    let decode = |v: f32| match v <= 0.04045 {
        true => v / 12.92,
        false => ((v + 0.055) / 1.055).powf(2.4),
    };
    Vec3::from(c.map(decode)) / 2f32.powf(exposure)
}

/// The frame `mode` shows of `model` and `reference` (`width` pixels a row, the divider at
/// `divider` of the width), at `exposure` stops.
pub fn compose(
    mode: Compare,
    model: &[Vec3],
    reference: &[Vec3],
    width: usize,
    divider: f32,
    exposure: f32,
) -> Vec<Vec3> {
    let column = (divider.clamp(0.0, 1.0) * width as f32) as usize;
    let white = shown_as([1.0; 3], exposure);
    (model.iter().zip(reference).enumerate())
        .map(|(i, (&m, &r))| match mode {
            Compare::Off => m,
            Compare::Split if i % width == column => white,
            Compare::Split if i % width < column => m,
            Compare::Split => r,
            Compare::Error => shown_as(ramp(relative_l1(m, r) / ERROR_SCALE), exposure),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_split_shows_the_model_left_and_the_reference_right_of_a_white_divider() {
        let (m, r) = (Vec3::splat(0.2), Vec3::splat(0.7));
        let shown = compose(Compare::Split, &[m; 8], &[r; 8], 4, 0.5, 0.0);
        assert_eq!(shown[..4], [m, m, Vec3::ONE, r]);
        assert_eq!(shown[4..], [m, m, Vec3::ONE, r]);
    }

    #[test]
    fn the_error_is_the_ramp_of_the_relative_l1_and_its_colour_survives_the_exposure() {
        let r = Vec3::new(1.0, 0.5, 0.25);
        assert_eq!(relative_l1(r, r), 0.0);
        let e = relative_l1(r * 1.5, r);
        assert!((e - 0.5 * 1.75 / (1.75 + 0.03)).abs() < 1e-6, "{e}");
        let shown = compose(Compare::Error, &[r * 1.5], &[r], 1, 0.0, 2.0)[0] * 4.0;
        let expect = shown_as(ramp(e), 0.0);
        assert!((shown - expect).abs().max_element() < 1e-6);
        assert_eq!(ramp(0.0), RAMP[0]);
        assert_eq!(ramp(7.0), RAMP[4]);
        assert_eq!(ramp(0.5), RAMP[2]);
    }

    #[test]
    fn l1_is_the_mean_absolute_difference() {
        let a = [Vec3::ZERO, Vec3::ONE];
        let b = [Vec3::new(0.3, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.4)];
        assert!((l1(&a, &b) - (0.3 + 0.6) / 6.0).abs() < 1e-6);
    }
}
