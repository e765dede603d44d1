//! What the engine trains on: a batch of pixel samples as plain slices, so that the engine
//! needs none of the training types.

/// `n` samples and the maps that light them.
#[derive(Clone, Copy)]
pub struct Samples<'a> {
    /// `[n, FEATURES]` pixel inputs.
    pub features: &'a [f32],
    /// `[n, 3]` reference radiance.
    pub radiance: &'a [f32],
    /// `[n, K, 3]` reference transfer vectors, for a linear design trained on them (empty:
    /// the radiance is the target).
    pub transfer: &'a [f32],
    /// `[n]`: which map lights each sample.
    pub view: &'a [i64],
    /// `[n, 3]`: what the prediction's channels are multiplied by (the map's normalisation).
    pub scale: &'a [f32],
    /// `[V, 3, W/2, W]` pre-processed maps.
    pub lights: &'a [f32],
    /// W of the maps.
    pub light_width: usize,
}

impl Samples<'_> {
    pub fn len(&self) -> usize {
        self.view.len()
    }

    pub fn is_empty(&self) -> bool {
        self.view.is_empty()
    }
}
