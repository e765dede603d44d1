//! The spherical-harmonics PRT baseline (Sloan et al. 2002), per pixel in a fixed view: each
//! pixel's transport onto the real SH basis is precomputed by path tracing (full global
//! illumination, BSDF sampling only), the lighting is projected onto the same basis, and
//! radiance is their per-channel dot product, on nprt-net's SH basis.

use glam::{Vec2, Vec3};
use nprt_net::encoding::spherical_harmonics::basis;
use nprt_scene::envmap::uv_to_direction;
use nprt_scene::{Camera, EnvMap};
use nprt_trace::{render_transport, RenderSettings, TraceScene};
use rayon::prelude::*;

/// SH coefficients (RGB) of `map` as placed in the world: radiance (as the renderer sees it,
/// bilinearly filtered) × basis, integrated over a lat-long grid of at least 512 × 256 cells
/// with each row's exact solid angle.
pub fn project(map: &EnvMap, bands: usize) -> Vec<Vec3> {
    let (w, h) = (map.width().max(512), map.height().max(256));
    let pi = std::f32::consts::PI;
    (0..h)
        .into_par_iter()
        .map(|row| {
            let mut acc = vec![Vec3::ZERO; bands * bands];
            let mut y = [0.0; 25];
            let v = (row as f32 + 0.5) / h as f32;
            let band =
                (pi * row as f32 / h as f32).cos() - (pi * (row + 1) as f32 / h as f32).cos();
            let d_omega = 2.0 * pi / w as f32 * band;
            for col in 0..w {
                let d =
                    map.to_world() * uv_to_direction(Vec2::new((col as f32 + 0.5) / w as f32, v));
                basis(bands, d, &mut y);
                let l = map.eval(d) * d_omega;
                for (a, yk) in acc.iter_mut().zip(&y) {
                    *a += l * *yk;
                }
            }
            acc
        })
        .reduce(
            || vec![Vec3::ZERO; bands * bands],
            |a, b| a.iter().zip(&b).map(|(x, y)| *x + *y).collect(),
        )
}

/// Per-pixel transport of one fixed view onto `bands`² SH functions.
pub struct ShTransport {
    pub bands: usize,
    /// [pixel][coefficient] RGB transport.
    pub transport: Vec<Vec<Vec3>>,
}

impl ShTransport {
    /// Path-traces the transport of `camera`'s view at `settings.spp` paths per pixel.
    pub fn precompute(
        ts: &TraceScene,
        camera: &Camera,
        bands: usize,
        settings: &RenderSettings,
    ) -> Self {
        let transport = render_transport(ts, camera, settings, bands * bands, &|d, _, out| {
            basis(bands, d, out)
        });
        ShTransport { bands, transport }
    }

    /// Keeps the first `bands` bands (transport of higher bands is a superset of lower ones).
    pub fn truncated(&self, bands: usize) -> Self {
        ShTransport {
            bands,
            transport: self
                .transport
                .iter()
                .map(|t| t[..bands * bands].to_vec())
                .collect(),
        }
    }

    /// Radiance of every pixel lit by `map` (scattered light only; background pixels are 0).
    pub fn shade(&self, map: &EnvMap) -> Vec<Vec3> {
        let c = project(map, self.bands);
        self.transport
            .iter()
            .map(|t| t.iter().zip(&c).map(|(tk, ck)| *tk * *ck).sum())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map_from(f: impl Fn(Vec3) -> Vec3) -> EnvMap {
        let (w, h) = (256, 128);
        let texels = (0..w * h)
            .map(|i| {
                let uv = Vec2::new(
                    ((i % w) as f32 + 0.5) / w as f32,
                    ((i / w) as f32 + 0.5) / h as f32,
                );
                f(uv_to_direction(uv))
            })
            .collect();
        EnvMap::from_texels("test", w, h, texels).unwrap()
    }

    #[test]
    fn projects_known_functions() {
        // L(d) = 2 + d.y: c0 = 2·√(4π), the band-1 y coefficient = 0.4886·4π/3, rest 0.
        let c = project(&map_from(|d| Vec3::splat(2.0 + d.y)), 3);
        assert!(
            (c[0].x - 2.0 * (4.0 * std::f32::consts::PI).sqrt()).abs() < 2e-2,
            "{:?}",
            c[0]
        );
        assert!(
            (c[1].x - 0.488_602_5 * 4.0 * std::f32::consts::PI / 3.0).abs() < 2e-2,
            "{:?}",
            c[1]
        );
        for (k, ck) in c.iter().enumerate().take(9).skip(2) {
            assert!(ck.abs().max_element() < 1e-2, "c{k} = {ck:?}");
        }
        // Rotating the map about +Y turns x into z; the y-only part stays.
        let rotated = project(&map_from(|d| Vec3::splat(1.0 + d.x)).rotated_y(90.0), 2);
        let plain = project(&map_from(|d| Vec3::splat(1.0 + d.x)), 2);
        assert!((rotated[0] - plain[0]).length() < 1e-2);
        assert!(
            (rotated[3].x.abs() + rotated[2].x.abs() - plain[3].x.abs()).abs() < 2e-2,
            "{rotated:?}"
        );
    }
}
