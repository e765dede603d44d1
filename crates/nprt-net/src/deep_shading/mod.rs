//! The Deep Shading baseline (Nalbach et al. 2017): a per-scene U-Net from G-buffer images to
//! radiance, trained on the same dataset as the Neural PRT designs, by the same loop
//! (`training::training_loop`: checkpoints with Adam's state, exact resume), on the CPU engine
//! or the GPU kernels (`kernel_steps`). The paper's comparison
//! gives it the lighting too: the map goes through the same light encoder (trained jointly)
//! and its code is added to the U-Net's bottleneck.

#[cfg(feature = "gpu")]
mod kernel_steps;
mod model;
mod options;
mod split;
mod train;
mod unet;

pub use crate::network::unet::DeepShading;
pub use model::{read_file, DeepShadingFile, DeepShadingModel, CONFIG_FILE, TAG};
pub use options::DeepShadingOptions;
pub use train::train;
pub use unet::feature_image;
