//! The real spherical-harmonics basis up to band 4 (25 functions), written out in closed form
//! (a few lines each) rather than taken from a crate: SH PRT projects light and transport on
//! it (nprt-eval), and the radiance cache encodes directions with it.

use glam::Vec3;

/// Real SH basis values of bands 0..`bands` (`bands`² values, at most 5 bands = 25) at the unit
/// direction `d`, in the usual order (l, m = −l..l) with Cartesian polynomials (Sloan 2008).
pub fn basis(bands: usize, d: Vec3, out: &mut [f32]) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use nprt_scene::envmap::uv_to_direction;

    #[test]
    fn basis_is_orthonormal() {
        // Midpoint quadrature over the sphere on a fine lat-long grid.
        let (w, h) = (400, 200);
        let mut gram = vec![0.0f64; 625];
        let mut y = [0.0; 25];
        for row in 0..h {
            let v = (row as f32 + 0.5) / h as f32;
            let dw = (2.0 * std::f64::consts::PI / w as f64)
                * (std::f64::consts::PI / h as f64)
                * ((v as f64) * std::f64::consts::PI).sin();
            for col in 0..w {
                basis(
                    5,
                    uv_to_direction(glam::Vec2::new((col as f32 + 0.5) / w as f32, v)),
                    &mut y,
                );
                for i in 0..25 {
                    for j in 0..25 {
                        gram[i * 25 + j] += (y[i] * y[j]) as f64 * dw;
                    }
                }
            }
        }
        for i in 0..25 {
            for j in 0..25 {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!(
                    (gram[i * 25 + j] - want).abs() < 2e-3,
                    "<Y{i}, Y{j}> = {}",
                    gram[i * 25 + j]
                );
            }
        }
    }
}
