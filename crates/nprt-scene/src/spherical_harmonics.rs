//! The real spherical-harmonics basis: bands up to 4 (25 functions) written out in closed form
//! (a few lines each), as the radiance cache evaluates them for every sample, and any band by
//! the associated Legendre recurrence, which the tests hold to the closed form. SH PRT projects
//! light and transport on it (nprt-eval), the dataset generator records transport on it
//! (`nprt generate --transfer`), the linear design projects its lighting on it (`LightBasis`),
//! and the radiance cache encodes directions with it.

use glam::Vec3;

/// The most bands [`basis`] evaluates: band 15, 256 functions.
pub const MAX_BANDS: usize = 16;

/// Real SH basis values of bands 0..`bands` (`bands`² values) at the unit direction `d`, in the
/// usual order (l, m = −l..l) with Cartesian polynomials (Sloan 2008): y-terms for m < 0,
/// x-terms for m > 0, no Condon-Shortley phase.
pub fn basis(bands: usize, d: Vec3, out: &mut [f32]) {
    assert!(bands <= MAX_BANDS, "{bands} SH bands: at most {MAX_BANDS}");
    if bands > 5 {
        return recurrence(bands, d, &mut out[..bands * bands]);
    }
    let (x, y, z) = (d.x, d.y, d.z);
    let (x2, y2, z2) = (x * x, y * y, z * z);
    let all = [
        0.282_094_8,
        0.488_602_5 * y,
        0.488_602_5 * z,
        0.488_602_5 * x,
        1.092_548_4 * x * y,
        1.092_548_4 * y * z,
        0.315_391_57 * (3.0 * z2 - 1.0),
        1.092_548_4 * x * z,
        0.546_274_2 * (x2 - y2),
        0.590_043_6 * y * (3.0 * x2 - y2),
        2.890_611_4 * x * y * z,
        0.457_045_8 * y * (5.0 * z2 - 1.0),
        0.373_176_34 * z * (5.0 * z2 - 3.0),
        0.457_045_8 * x * (5.0 * z2 - 1.0),
        1.445_305_7 * z * (x2 - y2),
        0.590_043_6 * x * (x2 - 3.0 * y2),
        2.503_343 * x * y * (x2 - y2),
        1.770_130_8 * y * z * (3.0 * x2 - y2),
        0.946_174_7 * x * y * (7.0 * z2 - 1.0),
        0.669_046_5 * y * z * (7.0 * z2 - 3.0),
        0.105_785_55 * (35.0 * z2 * z2 - 30.0 * z2 + 3.0),
        0.669_046_5 * x * z * (7.0 * z2 - 3.0),
        0.473_087_34 * (x2 - y2) * (7.0 * z2 - 1.0),
        1.770_130_8 * x * z * (x2 - 3.0 * y2),
        0.625_835_7 * (x2 * (x2 - 3.0 * y2) - y2 * (3.0 * x2 - y2)),
    ];
    out[..bands * bands].copy_from_slice(&all[..bands * bands]);
}

/// Any band: Y_l^m = N_l^|m| · Q_l^|m|(z) · (Re or Im of (x + iy)^|m|), with Q the associated
/// Legendre function without its (1 − z²)^(m/2) factor, which the complex power carries.
/// Evaluated in f64: the recurrence's terms grow with the band and cancel.
fn recurrence(bands: usize, d: Vec3, out: &mut [f32]) {
    let (x, y, z) = (d.x as f64, d.y as f64, d.z as f64);
    let mut q = [[0.0f64; MAX_BANDS]; MAX_BANDS];
    let mut power = (1.0f64, 0.0f64);
    for m in 0..bands {
        // Q_m^m = (2m − 1)!!, Q_{m+1}^m = (2m + 1) z Q_m^m, then the three-term recurrence.
        q[m][m] = (1..=m).map(|k| (2 * k - 1) as f64).product();
        if m + 1 < bands {
            q[m + 1][m] = (2 * m + 1) as f64 * z * q[m][m];
        }
        for l in m + 2..bands {
            q[l][m] = ((2 * l - 1) as f64 * z * q[l - 1][m] - (l + m - 1) as f64 * q[l - 2][m])
                / (l - m) as f64;
        }
        for (l, q_l) in q.iter().enumerate().take(bands).skip(m) {
            let ratio: f64 = (l - m + 1..=l + m).map(|k| 1.0 / k as f64).product();
            let mut norm = ((2 * l + 1) as f64 / (4.0 * std::f64::consts::PI) * ratio).sqrt();
            if m > 0 {
                norm *= std::f64::consts::SQRT_2;
            }
            let at = l * l + l;
            out[at + m] = (norm * q_l[m] * power.0) as f32;
            if m > 0 {
                out[at - m] = (norm * q_l[m] * power.1) as f32;
            }
        }
        power = (power.0 * x - power.1 * y, power.0 * y + power.1 * x);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envmap::uv_to_direction;

    #[test]
    fn the_recurrence_is_the_closed_form() {
        let mut closed = [0.0; 25];
        let mut general = [0.0; 25];
        for i in 0..50 {
            let uv = glam::Vec2::new((i as f32 * 0.618_034) % 1.0, (i as f32 + 0.5) / 50.0);
            let d = uv_to_direction(uv);
            basis(5, d, &mut closed);
            recurrence(5, d, &mut general);
            for (k, (a, b)) in closed.iter().zip(&general).enumerate() {
                assert!(
                    (a - b).abs() < 1e-5,
                    "Y{k} at {d}: {a} closed, {b} recurrence"
                );
            }
        }
    }

    /// Midpoint quadrature over the sphere on a `w` × `w/2` lat-long grid: the closed form's
    /// five bands and the recurrence's nine are orthonormal.
    #[test]
    fn basis_is_orthonormal() {
        for (bands, w) in [(5, 400), (9, 240)] {
            let (h, k) = (w / 2, bands * bands);
            let mut gram = vec![0.0f64; k * k];
            let mut y = vec![0.0; k];
            for row in 0..h {
                let v = (row as f32 + 0.5) / h as f32;
                let dw = (2.0 * std::f64::consts::PI / w as f64)
                    * (std::f64::consts::PI / h as f64)
                    * ((v as f64) * std::f64::consts::PI).sin();
                for col in 0..w {
                    let uv = glam::Vec2::new((col as f32 + 0.5) / w as f32, v);
                    basis(bands, uv_to_direction(uv), &mut y);
                    for i in 0..k {
                        for j in 0..k {
                            gram[i * k + j] += (y[i] * y[j]) as f64 * dw;
                        }
                    }
                }
            }
            for i in 0..k {
                for j in 0..k {
                    let want = if i == j { 1.0 } else { 0.0 };
                    let got = gram[i * k + j];
                    assert!(
                        (got - want).abs() < 3e-3,
                        "{bands} bands: <Y{i}, Y{j}> = {got}"
                    );
                }
            }
        }
    }
}
