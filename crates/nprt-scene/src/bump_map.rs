//! Mitsuba 3's `bumpmap`: a height field over the surface's uv that tilts the shading normal,
//! as if the surface were displaced along its normal by `scale` × height. Only the height's
//! gradient matters (constant offsets change nothing), and the base surface's own curvature is
//! neglected, as Mitsuba does. How the tilted normal is oriented towards the viewer and how
//! directions between it and the base surface are shadowed is the tracer's business.

use glam::{Vec2, Vec3};

use crate::texture::Texture;

#[derive(Clone, Debug)]
pub struct BumpMap {
    /// Read through its luminance.
    pub height: Texture,
    /// Multiplies the height's gradient (Mitsuba's `scale`, default 1).
    pub scale: f32,
    /// Mitsuba's `twosided` wraps the bump map rather than the other way round: seen from the
    /// back, the bumped normal is mirrored across the surface instead of negated (the same
    /// bumps seen from the back, rather than the dents they make there).
    pub mirrored_behind: bool,
}

impl BumpMap {
    /// The bumped normal at `uv` of a surface with shading normal `ns` and position
    /// derivatives `dp_du`, `dp_dv`, on the side of the geometric normal `ng`.
    pub fn normal(&self, uv: Vec2, ns: Vec3, ng: Vec3, dp_du: Vec3, dp_dv: Vec3) -> Vec3 {
        let g = self.scale * self.height.luminance_gradient(uv);
        let du = dp_du + ns * (g.x - ns.dot(dp_du));
        let dv = dp_dv + ns * (g.y - ns.dot(dp_dv));
        let n = du.cross(dv).normalize_or(ns);
        if n.dot(ng) < 0.0 {
            -n
        } else {
            n
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::Bitmap;
    use glam::Affine2;
    use std::sync::Arc;

    /// A height rising linearly along u on the plane z = 0 tilts the normal by atan(slope).
    #[test]
    fn a_height_ramp_tilts_the_normal_by_its_slope() {
        // Texel values 0, 1, 2, 3 along x: luminance gradient 1 per texel, 4 per unit u.
        let texels = (0..4).map(|i| Vec3::splat(i as f32)).collect();
        let bump = BumpMap {
            height: Texture::Bitmap {
                image: Arc::new(Bitmap {
                    width: 4,
                    height: 1,
                    texels,
                }),
                to_uv: Affine2::IDENTITY,
                factor: Vec3::ONE,
            },
            scale: 0.5,
            mirrored_behind: false,
        };
        // u runs along x over 2 units (Mitsuba's rectangle): slope 0.5 · 4 / 2 = 1, so 45°.
        let n = bump.normal(
            Vec2::new(0.5, 0.5),
            Vec3::Z,
            Vec3::Z,
            Vec3::X * 2.0,
            Vec3::Y * 2.0,
        );
        let expected = Vec3::new(-1.0, 0.0, 1.0).normalize();
        assert!((n - expected).length() < 1e-6, "{n}");
        // Oriented to the geometric normal's side, whichever way the parametrisation turns.
        let n = bump.normal(
            Vec2::new(0.5, 0.5),
            Vec3::Z,
            Vec3::Z,
            Vec3::X * 2.0,
            -Vec3::Y * 2.0,
        );
        assert!(n.z > 0.0 && (n.z - expected.z).abs() < 1e-6, "{n}");
        // A flat height leaves the shading normal as it was.
        let flat = BumpMap {
            height: Texture::constant(0.7),
            ..bump
        };
        let ns = Vec3::new(0.1, 0.2, 1.0).normalize();
        let n = flat.normal(Vec2::ZERO, ns, Vec3::Z, Vec3::X, Vec3::Y);
        assert!((n - ns).length() < 1e-6);
    }
}
