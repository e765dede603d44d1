//! An indoor-style lighting generator: bright window and lamp regions over a dim surround,
//! every choice drawn from the seed.

use anyhow::{bail, Result};
use glam::{Vec2, Vec3};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

use crate::envmap::EnvMap;

/// An indoor-style map: a dim, slightly graded surround with 1–3 bright rectangular windows or
/// lamps of random size, place, colour and strength, all drawn from `seed`.
pub fn indoor(seed: u64, width: usize) -> Result<EnvMap> {
    if width < 8 || !width.is_multiple_of(2) {
        bail!("indoor map width {width} must be even and at least 8");
    }
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x1d00_2d00);
    let (w, h) = (width, width / 2);
    let wall = Vec3::new(
        rng.random_range(0.7..1.0),
        rng.random_range(0.7..1.0),
        rng.random_range(0.7..1.0),
    ) * rng.random_range(0.04..0.12);
    struct Light {
        centre: Vec2,
        half: Vec2,
        radiance: Vec3,
    }
    let n = rng.random_range(1..=3);
    let lights: Vec<Light> = (0..n)
        .map(|_| {
            let lamp = rng.random_bool(0.4);
            let warm = rng.random_range(0.0..1.0f32);
            let tint = Vec3::new(1.0, 0.85 + 0.15 * (1.0 - warm), 0.6 + 0.4 * (1.0 - warm));
            if lamp {
                // Small ceiling lamp, high up.
                Light {
                    centre: Vec2::new(rng.random_range(0.0..1.0), rng.random_range(0.05..0.25)),
                    half: Vec2::new(rng.random_range(0.01..0.03), rng.random_range(0.01..0.03)),
                    radiance: tint * rng.random_range(20.0..60.0),
                }
            } else {
                // Window: wide, around the horizon or above it.
                Light {
                    centre: Vec2::new(rng.random_range(0.0..1.0), rng.random_range(0.3..0.48)),
                    half: Vec2::new(rng.random_range(0.03..0.09), rng.random_range(0.05..0.12)),
                    radiance: tint * rng.random_range(3.0..12.0),
                }
            }
        })
        .collect();
    let mut texels = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let uv = Vec2::new((x as f32 + 0.5) / w as f32, y as f32 / (h - 1) as f32);
            // Ceiling a little brighter than the floor.
            let mut c = wall * (1.3 - 0.8 * uv.y);
            for l in &lights {
                let du = (uv.x - l.centre.x + 0.5).rem_euclid(1.0) - 0.5;
                if du.abs() < l.half.x && (uv.y - l.centre.y).abs() < l.half.y {
                    c += l.radiance;
                }
            }
            texels.push(c);
        }
    }
    EnvMap::from_texels(&format!("builtin:indoor:{seed}"), w, h, texels)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::luminance;

    #[test]
    fn indoor_maps_depend_on_seed_only() {
        let a = indoor(7, 64).unwrap();
        let b = indoor(7, 64).unwrap();
        let c = indoor(8, 64).unwrap();
        assert_eq!(a.texels(), b.texels());
        assert_ne!(a.texels(), c.texels());
        let peak = a.texels().iter().map(|&t| luminance(t)).fold(0.0, f32::max);
        assert!(
            peak > 20.0 * luminance(a.mean_radiance()) / 2.0,
            "lights should stand out"
        );
    }
}
