//! The sRGB transfer curve: what 8-bit image files store. Inside nprt colour is linear Rec.709.

/// The sRGB transfer function, encoded value in [0, 1] to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The inverse of [`srgb_to_linear`] on [0, 1]; values outside are clamped.
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curves_invert_each_other_and_hit_known_values() {
        for i in 0..=100 {
            let v = i as f32 / 100.0;
            assert!((linear_to_srgb(srgb_to_linear(v)) - v).abs() < 1e-5, "{v}");
        }
        // Mid-grey: sRGB 0.5 is 21.4% linear; the knee is continuous.
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
        assert!((srgb_to_linear(0.04045) - 0.04045 / 12.92).abs() < 1e-7);
        assert!((linear_to_srgb(2.0) - 1.0).abs() < 1e-6, "clamped to white");
    }
}
