//! The views a dataset is asked for and how each is rendered, stated once for `generate`'s
//! options and the plan made from them: counts and resolutions per split, samples per pixel,
//! and the seed, jitter and mixing of the random choices. `Default` is the recipe for a 2-core
//! CPU (400 + 40 views at 128², 64 spp, about 7 minutes on builtin:room); the paper used 3000
//! views at 256² and 200 at 400².

use super::manifest::Jitter;

/// What views a dataset holds and how they are rendered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSpec {
    pub train_views: u64,
    pub test_views: u64,
    pub train_resolution: [u32; 2],
    pub test_resolution: [u32; 2],
    /// Samples per pixel of the training views, every one through the pixel centre.
    pub spp: u32,
    /// Samples per pixel of the test views, rendered as two halves (so even, at least 2).
    pub test_spp: u32,
    /// Seed of every random choice: the same seed gives byte-identical views.
    pub seed: u64,
    /// Exposure and white-balance jitter of the training views' maps, in stops.
    pub jitter: Jitter,
    /// The most maps a training view's lighting mixes: its own and up to this many − 1 others
    /// of the training maps, each rotated and scaled at random (1: one map a view).
    pub mix_maps: u32,
}

impl Default for ViewSpec {
    fn default() -> Self {
        ViewSpec {
            train_views: 400,
            test_views: 40,
            train_resolution: [128; 2],
            test_resolution: [128; 2],
            spp: 64,
            test_spp: 1024,
            seed: 0,
            jitter: Jitter {
                exposure: 1.0,
                tint: 0.3,
            },
            mix_maps: 1,
        }
    }
}
