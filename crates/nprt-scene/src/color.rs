//! Colour conventions: linear Rec.709 RGB everywhere inside nprt; sRGB only at image files
//! (`nprt_io`).

use glam::Vec3;

/// Linear Rec.709 luminance, the weights Mitsuba 3 uses for importance sampling.
pub fn luminance(c: Vec3) -> f32 {
    0.212671 * c.x + 0.715160 * c.y + 0.072169 * c.z
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn luminance_weights_sum_to_one() {
        assert_eq!(luminance(Vec3::ONE), 0.212671 + 0.715160 + 0.072169);
    }
}
