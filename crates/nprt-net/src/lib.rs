//! nprt-net: the learned part of Neural PRT. It owns the light encoder, the four transport
//! designs, the model folder format (weights plus config) and training on a dataset folder.
//! It reads datasets through nprt-data and environment maps through nprt-scene; it must not
//! trace rays or write datasets, and it knows nothing of evaluation or frame rendering.
//!
//! Network code is device-generic: it runs on whatever burn `Device` its tensors live on
//! (the flex CPU backend here; a GPU backend by enabling its burn feature).

pub mod curves;
pub mod data;
pub mod design;
pub mod encoder;
pub mod layers;
pub mod loss;
pub mod model;
pub mod train;

pub use burn;
pub use burn::tensor::Device;
pub use design::{Design, NprtNet, FEATURES};
pub use encoder::{LightEncoder, LightInput};
pub use layers::{Activation, Init};
pub use loss::log_l1;
pub use model::{layer_table, load_model, ModelConfig, ModelFile, DEFAULT_ENCODER_WIDTH};
pub use train::{measure_throughput, train, TrainOptions, TrainSummary};
