//! A bump-mapped frame: Mitsuba 3's `bumpmap` drop of light between the two normals and
//! Estevez et al.'s terminator shadowing.

use glam::Vec3;

use super::Bsdf;

impl<'a> Bsdf<'a> {
    /// The BSDF in a frame a bump map tilted away from the surface's normal `unbumped` (given in
    /// the tilted frame), as Mitsuba 3's `bumpmap`: light on opposite sides of the two normals
    /// is dropped, and the rest shadowed by Estevez et al.'s terminator term (Ray Tracing Gems,
    /// 2019) so that the tilt does not leave hard shadow edges.
    pub fn with_bump(mut self, unbumped: Option<Vec3>) -> Self {
        self.unbumped = unbumped;
        self
    }

    /// The bump map's factor on light along `wi`: 1 without one.
    pub(super) fn bump_factor(&self, wi: Vec3) -> f32 {
        let Some(n) = self.unbumped else {
            return 1.0;
        };
        let cos = wi.dot(n);
        if cos * wi.z <= 0.0 {
            return 0.0;
        }
        let tan2 = |c: f32| (1.0 - c * c).max(0.0) / (c * c);
        let a2 = (0.125 * tan2(n.z)).min(1.0);
        2.0 / (1.0 + (1.0 + a2 * tan2(cos)).sqrt())
    }
}
