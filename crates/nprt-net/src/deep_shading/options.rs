//! How the Deep Shading baseline is trained, each default stated once here.

use serde::{Deserialize, Serialize};

use crate::encoding::map_norm::MapNorm;
use crate::model::config::{DEFAULT_ENCODER_WIDTH, DEFAULT_MAP_NORM};
use crate::training::schedule::Schedule;

/// The Deep Shading run's settings (saved in its config).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeepShadingOptions {
    #[serde(flatten)]
    pub schedule: Schedule,
    /// Whole views per step.
    pub batch_views: usize,
    /// Width W of the light encoder's W × W/2 input.
    pub encoder_width: usize,
    /// How the map is normalised for the encoder (absent in older files: the paper's mean).
    #[serde(default)]
    pub map_norm: MapNorm,
}

impl Default for DeepShadingOptions {
    fn default() -> Self {
        DeepShadingOptions {
            // Its learning rate too: 1e-3 was measured to kill this ReLU U-Net (every
            // activation dead, the output a constant).
            schedule: Schedule::default(),
            batch_views: 4,
            encoder_width: DEFAULT_ENCODER_WIDTH,
            map_norm: DEFAULT_MAP_NORM,
        }
    }
}
