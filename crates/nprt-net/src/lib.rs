//! nprt-net: the learned part of Neural PRT. It owns the light encoder, the four transport
//! designs and the hash-grid position encoding beyond them, the Deep Shading baseline network,
//! the model folder format (weights plus config) and the one training loop every network goes
//! through (checkpoints, exact resume).
//! It reads datasets through nprt-data and environment maps through nprt-scene; it must not
//! trace rays or write datasets, and it knows nothing of evaluation or frame rendering.
//!
//! Network code is device-generic: it runs on whatever burn `Device` its tensors live on
//! (the flex CPU backend here; a GPU backend by enabling its burn feature). On the CPU in f32
//! the transport networks train and infer through [`cpu`], a hand-written engine held to
//! burn's autodiff by tests, because burn's graph was slower than PyTorch on SIREN layers.
//!
//! ```
//! use nprt_net::{Design, Device, Init, ModelConfig};
//!
//! // The paper's diffuse/specular design, with its own default activation (SIREN).
//! let net = ModelConfig::new(Design::Dsep, None).build(&mut Init::new(0, &Device::flex()));
//! let paper = Design::Dsep.paper_params() as f64;
//! assert!((net.transport_params() as f64 / paper - 1.0).abs() < 0.05);
//! ```

mod activation;
mod batch;
mod calibration;
mod checkpoint;
mod compute;
pub mod cpu;
pub mod curves;
pub mod data;
pub mod deep_shading;
mod design;
mod direct_light;
pub mod encoder;
mod epoch_plan;
mod features;
pub mod hash_grid;
mod init;
pub mod loss;
mod lr_schedule;
mod map_norm;
mod mlp;
pub mod model;
mod named;
mod options;
mod position_encoding;
mod throughput;
mod track;
mod train;
pub mod trainer;
mod validation;

pub use activation::{Activation, OMEGA_0};
pub use batch::{Batch, Engine};
pub use burn;
pub use burn::tensor::Device;
pub use calibration::{level_gain, Calibration, LEVEL_SAMPLES};
pub use checkpoint::RunState;
pub use compute::{device_name, finish, is_cpu, Backend, Compute};
pub use design::{Design, NprtNet, TRANSPORT_CODE};
pub use direct_light::DirectLight;
pub use encoder::{LightEncoder, LightInput};
pub use features::{feature, gbuffer_features, pixel_features, FEATURES};
pub use init::{conv2d, Init};
pub use loss::{log_l1, Loss};
pub use lr_schedule::LrSchedule;
pub use map_norm::MapNorm;
pub use mlp::Mlp;
pub use model::{
    layer_table, load_model, ModelConfig, ModelFile, DEFAULT_ENCODER_WIDTH, DEFAULT_MAP_NORM,
};
pub use options::{recipe_rate, TrainOptions};
pub use position_encoding::PositionEncoding;
pub use throughput::{measure_inference, measure_throughput, median, InferenceSpeed};
pub use track::{Track, TrackKind};
pub use train::train;
pub use trainer::{Objective, Schedule, TrainSummary};
pub use validation::validation_loss;
