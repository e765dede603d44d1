//! How an environment map is normalised for the encoder and its level restored at the output.

use crate::choice::named_choice;

/// What a map is divided by before the encoder sees it; the network's radiance is multiplied
/// by the same. Radiance is linear in the lighting, channel by channel, so either is exact under
/// the change it divides out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MapNorm {
    /// The paper's: one mean over texels and channels, exact under a change of intensity. The
    /// map's colour reaches the prediction only through what the encoder learnt from the
    /// training maps. Models saved before the choice existed were trained this way.
    #[default]
    Mean,
    /// Each channel by its own mean, restored per channel: exact under any per-channel gain
    /// (white balance, a warm or cool tint), so the colour of a held-out map need not be
    /// learnt; the encoder sees only how the colour varies over the map.
    Channel,
}

named_choice!(MapNorm, "map normalisation", {
    Mean => "mean",
    Channel => "channel",
});

impl MapNorm {
    /// The divisor of each channel for per-channel map means `mean`.
    pub fn scale(self, mean: [f32; 3]) -> [f32; 3] {
        let s = match self {
            MapNorm::Mean => [(mean[0] + mean[1] + mean[2]) / 3.0; 3],
            MapNorm::Channel => mean,
        };
        s.map(|v| v.max(f32::MIN_POSITIVE))
    }
}
