//! A view's G-buffer as the Deep Shading U-Net's input image (the network itself is
//! `network::unet`).

use nprt_trace::GBuffer;

use crate::encoding::features::gbuffer_features;
use crate::encoding::features::FEATURES;

/// A view's G-buffer as a [19, H', W'] feature image, zero on the background and padded to
/// multiples of 8; returns the padded size too.
pub fn feature_image(
    bounds: &[[f32; 3]; 2],
    g: &GBuffer,
    width: usize,
    height: usize,
) -> (Vec<f32>, usize, usize) {
    let (pw, ph) = (width.div_ceil(8) * 8, height.div_ceil(8) * 8);
    let mut img = vec![0.0; FEATURES * pw * ph];
    for i in (0..g.mask.len()).filter(|&i| g.mask[i] > 0.5) {
        let f = gbuffer_features(bounds, g, i);
        let (x, y) = (i % width, i / width);
        for (k, v) in f.iter().enumerate() {
            img[k * pw * ph + y * pw + x] = *v;
        }
    }
    (img, pw, ph)
}
