//! The outdoor sky with sun from the Preetham et al. 1999 analytic daylight model (kept by
//! hand: no maintained crate implements it).

use anyhow::{bail, Result};
use glam::{Vec2, Vec3};

use crate::envmap::{direction_to_uv, uv_to_direction, EnvMap};
use crate::luminance;

/// Parameters of the outdoor sky.
#[derive(Clone, Copy, Debug)]
pub struct SkyParams {
    /// Sun elevation above the horizon, degrees (0..90).
    pub elevation: f32,
    /// Sun azimuth, degrees, measured like the map's u coordinate (0 = −Z, 90 = +X).
    pub azimuth: f32,
    /// Atmospheric turbidity, 2 (clear) to 10 (hazy), the range the model was fitted on.
    pub turbidity: f32,
    /// Map width in texels (height is half).
    pub width: usize,
}

impl Default for SkyParams {
    fn default() -> Self {
        SkyParams {
            elevation: 35.0,
            azimuth: 120.0,
            turbidity: 3.0,
            width: 256,
        }
    }
}

/// Angular radius of the sun disk. Larger than the real 0.27° so a 256-wide map resolves it
/// (a texel is 1.4°); the disk's radiance is scaled to keep its irradiance.
const SUN_RADIUS_DEG: f32 = 1.5;

/// Perez et al. luminance distribution F(θ, γ).
fn perez(c: [f32; 5], cos_theta: f32, gamma: f32) -> f32 {
    (1.0 + c[0] * (c[1] / cos_theta.max(0.01)).exp())
        * (1.0 + c[2] * (c[3] * gamma).exp() + c[4] * gamma.cos().powi(2))
}

/// Linear Rec.709 RGB from CIE xyY.
fn xyy_to_rgb(x: f32, y: f32, big_y: f32) -> Vec3 {
    let (xx, zz) = (x / y * big_y, (1.0 - x - y) / y * big_y);
    Vec3::new(
        3.2406 * xx - 1.5372 * big_y - 0.4986 * zz,
        -0.9689 * xx + 1.8758 * big_y + 0.0415 * zz,
        0.0557 * xx - 0.2040 * big_y + 1.0570 * zz,
    )
    .max(Vec3::ZERO)
}

/// Preetham, Shirley and Smits, "A Practical Analytic Model for Daylight" (SIGGRAPH 1999).
pub fn sky(p: SkyParams) -> Result<EnvMap> {
    if !(0.5..=90.0).contains(&p.elevation)
        || !(1.7..=10.0).contains(&p.turbidity)
        || p.width < 8
        || !p.width.is_multiple_of(2)
    {
        bail!("sky parameters out of range: elevation {}° (0.5..90), turbidity {} (1.7..10), width {} (even, ≥ 8)", p.elevation, p.turbidity, p.width);
    }
    let t = p.turbidity;
    let theta_s = (90.0 - p.elevation).to_radians();
    let sun_dir = uv_to_direction(Vec2::new(p.azimuth / 360.0, theta_s / std::f32::consts::PI));
    let (w, h) = (p.width, p.width / 2);
    let mut texels = perez_sky(t, theta_s, sun_dir, w, h);
    // Horizontal sky irradiance (Riemann sum over texels), which sets the sun and ground.
    let solid = |y: usize| {
        let th = y as f32 / (h - 1) as f32 * std::f32::consts::PI;
        th.sin() * (std::f32::consts::PI / (h - 1) as f32) * (2.0 * std::f32::consts::PI / w as f32)
    };
    let mut e_sky = Vec3::ZERO;
    for y in 0..h {
        for x in 0..w {
            let d = texel_direction(x, y, w, h);
            if d.y > 0.0 {
                e_sky += texels[y * w + x] * d.y * solid(y);
            }
        }
    }
    // Sun: direct normal irradiance ~4× the sky's horizontal irradiance for a clear sky,
    // reddened by a Rayleigh-like transmittance along the air mass (Kasten-Young).
    let elev = p.elevation;
    let air_mass = 1.0 / (elev.to_radians().sin() + 0.50572 * (elev + 6.07995).powf(-1.6364));
    let tau = Vec3::new(0.06, 0.11, 0.24) * (t / 3.0);
    let transmittance = Vec3::new(
        (-tau.x * air_mass).exp(),
        (-tau.y * air_mass).exp(),
        (-tau.z * air_mass).exp(),
    );
    let sun_omega = 2.0 * std::f32::consts::PI * (1.0 - SUN_RADIUS_DEG.to_radians().cos());
    let sun_radiance =
        transmittance * (4.0 * luminance(e_sky) / (sun_omega * luminance(transmittance)));
    let ground = e_sky * (0.3 / std::f32::consts::PI);
    for y in 0..h {
        for x in 0..w {
            let d = texel_direction(x, y, w, h);
            let texel = &mut texels[y * w + x];
            if d.y < 0.0 {
                *texel = ground;
            }
            if d.dot(sun_dir).clamp(-1.0, 1.0).acos() < SUN_RADIUS_DEG.to_radians() {
                *texel += sun_radiance;
            }
        }
    }
    // Guarantee the sun lands on at least one texel whatever the resolution.
    let uv = direction_to_uv(sun_dir);
    let (sx, sy) = (
        ((uv.x * w as f32) as usize).min(w - 1),
        ((uv.y * (h - 1) as f32).round() as usize).min(h - 1),
    );
    if luminance(texels[sy * w + sx]) < luminance(sun_radiance) {
        texels[sy * w + sx] += sun_radiance;
    }
    let name = format!("builtin:sky:{}:{}:{}", p.elevation, p.azimuth, p.turbidity);
    EnvMap::from_texels(&name, w, h, texels)
}

/// The Perez et al. sky of turbidity `t` with the sun at zenith angle `theta_s` towards
/// `sun_dir` on a `w × h` lat-long grid, in scene units (no sun disc, no ground).
fn perez_sky(t: f32, theta_s: f32, sun_dir: Vec3, w: usize, h: usize) -> Vec<Vec3> {
    let coef_y = [
        0.1787 * t - 1.4630,
        -0.3554 * t + 0.4275,
        -0.0227 * t + 5.3251,
        0.1206 * t - 2.5771,
        -0.0670 * t + 0.3703,
    ];
    let coef_x = [
        -0.0193 * t - 0.2592,
        -0.0665 * t + 0.0008,
        -0.0004 * t + 0.2125,
        -0.0641 * t - 0.8989,
        -0.0033 * t + 0.0452,
    ];
    let coef_yc = [
        -0.0167 * t - 0.2608,
        -0.0950 * t + 0.0092,
        -0.0079 * t + 0.2102,
        -0.0441 * t - 1.6537,
        -0.0109 * t + 0.0529,
    ];
    let chi = (4.0 / 9.0 - t / 120.0) * (std::f32::consts::PI - 2.0 * theta_s);
    let zenith_y = ((4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192).max(0.05);
    let poly = |m: [[f32; 4]; 3]| {
        let th = [theta_s.powi(3), theta_s.powi(2), theta_s, 1.0];
        let row = |r: [f32; 4]| r.iter().zip(th).map(|(a, b)| a * b).sum::<f32>();
        t * t * row(m[0]) + t * row(m[1]) + row(m[2])
    };
    let zenith_x = poly([
        [0.00166, -0.00375, 0.00209, 0.0],
        [-0.02903, 0.06377, -0.03202, 0.00394],
        [0.11693, -0.21196, 0.06052, 0.25886],
    ]);
    let zenith_yc = poly([
        [0.00275, -0.00610, 0.00317, 0.0],
        [-0.04214, 0.08970, -0.04153, 0.00516],
        [0.15346, -0.26756, 0.06670, 0.26688],
    ]);
    // kcd/m² to scene units: a clear zenith comes out near 1.
    let unit = 1.0 / 8.0;
    let mut texels = vec![Vec3::ZERO; w * h];
    for y in 0..h {
        for x in 0..w {
            let d = texel_direction(x, y, w, h);
            let cos_theta = d.y.max(0.0);
            let gamma = d.dot(sun_dir).clamp(-1.0, 1.0).acos();
            let f = |c: [f32; 5], z: f32| z * perez(c, cos_theta, gamma) / perez(c, 1.0, theta_s);
            texels[y * w + x] = xyy_to_rgb(
                f(coef_x, zenith_x),
                f(coef_yc, zenith_yc),
                f(coef_y, zenith_y),
            ) * unit;
        }
    }
    texels
}

/// The direction through texel (`x`, `y`) of a `w × h` lat-long map: its centre in u, its row
/// from pole to pole in v.
fn texel_direction(x: usize, y: usize, w: usize, h: usize) -> Vec3 {
    uv_to_direction(Vec2::new(
        (x as f32 + 0.5) / w as f32,
        y as f32 / (h - 1) as f32,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sky_is_brightest_at_the_sun_and_bluer_than_the_sun() {
        let m = sky(SkyParams {
            elevation: 40.0,
            azimuth: 90.0,
            ..Default::default()
        })
        .unwrap();
        let sun = uv_to_direction(Vec2::new(0.25, 50.0 / 180.0));
        let brightest = m.texels().iter().map(|&t| luminance(t)).fold(0.0, f32::max);
        assert!((luminance(m.eval(sun)) - brightest).abs() / brightest < 0.5);
        let zenith = m.eval(Vec3::Y);
        assert!(zenith.z > zenith.x, "clear zenith should be blue: {zenith}");
        // Most sampled directions point at the sun.
        let hits = (0..1000)
            .filter(|k| {
                m.sample(Vec3::new(
                    (*k as f32 * 0.618).fract(),
                    (*k as f32 + 0.5) / 1000.0,
                    0.5,
                ))
                .0
                .dot(sun)
                    > 0.99
            })
            .count();
        assert!(hits > 500, "{hits}");
    }
}
