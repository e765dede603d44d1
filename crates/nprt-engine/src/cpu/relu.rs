//! ReLU on the CPU engine's planes, and its gradient: the light encoder's blocks and the U-Net's
//! convolutions take them (dense layers fuse theirs into the bias pass, `cpu::dense`).

/// ReLU in place.
#[inline]
pub fn relu(x: &mut [f32]) {
    x.iter_mut().for_each(|v| *v = v.max(0.0));
}

/// The gradient `d` through a ReLU whose output was `y`, in place: it passes where `y` > 0.
#[inline]
pub fn relu_back(d: &mut [f32], y: &[f32]) {
    d.iter_mut()
        .zip(y)
        .for_each(|(d, &y)| *d = if y > 0.0 { *d } else { 0.0 });
}
