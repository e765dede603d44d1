//! nprt-net: the learned part of Neural PRT. It owns the light encoder, the four transport
//! designs and the hash-grid position encoding beyond them, the Deep Shading baseline network,
//! the model folder format (weights plus config) and the one training loop every network goes
//! through (checkpoints, exact resume). Its modules keep the pieces apart, as tiny-cuda-nn
//! does, in layers, each using only those before it:
//! 1. the shared pieces: `precision`, `parameters` (the one weight type every network is),
//!    `init` (how parameters start), `loss`;
//! 2. `encoding` (what the networks see), then `network` (layers, encoder, track kinds and
//!    plans, designs, the U-Net, the radiance cache), then `optimiser` (Adam, and the steps an engine
//!    takes) and `model` (config and folder);
//! 3. the engines: `cpu` (the CPU engine, on the networks' own weights), `gpu` (our own GPU
//!    kernels, feature `gpu`, which read the same weights), `shading` (a trained network as
//!    frames run it, on either) and `engine` (what `--device` resolves to, and the one place
//!    that picks an engine's network);
//! 4. `training` (data, batches, schedule, the loop, each engine's steps);
//! 5. `deep_shading` and `bench`.
//!
//! It reads datasets through nprt-data and environment maps through nprt-scene; it must not
//! trace rays or write datasets, and it knows nothing of evaluation or frame rendering.
//!
//! No framework: `--device` resolves into an [`Engine`] that runs the steps and frames, the
//! CPU engine ([`cpu`]) or our own GPU kernels ([`gpu`], feature `gpu`), both on the
//! weights [`network`] defines. The gradient checks hold them to f64 finite differences.
//!
//! ```
//! use nprt_net::{Design, Init, ModelConfig};
//!
//! // The paper's diffuse/specular design, with its own default activation (SIREN).
//! let net = ModelConfig::new(Design::Dsep, None).build(&mut Init::new(0));
//! let paper = Design::Dsep.paper_params() as f64;
//! assert!((net.transport_params() as f64 / paper - 1.0).abs() < 0.05);
//! ```

pub mod bench;
pub mod cpu;
pub mod deep_shading;
pub mod encoding;
mod engine;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod model;
pub mod network;
mod shading;
pub mod training;

// The engine below the networks (nprt-engine), under the paths the networks have always used.
use nprt_engine::{choice, precision};
pub use nprt_engine::{init, loss, optimiser, parameters};

#[cfg(feature = "gpu")]
pub use bench::throughput::profile_kernels;
pub use bench::throughput::{measure_inference, measure_throughput, median, InferenceSpeed};
pub use encoding::features::{feature, gbuffer_features, pixel_features, position_frame, FEATURES};
pub use encoding::map_norm::MapNorm;
pub use encoding::position_encoding::PositionEncoding;
pub use engine::{finish, Compute, Engine};
pub use init::Init;
pub use loss::Loss;
pub use model::config::{ModelConfig, DEFAULT_ENCODER_WIDTH, DEFAULT_MAP_NORM};
pub use model::direct_light::DirectLight;
pub use model::folder::{load_model, read_model_file, ModelFile};
pub use model::layer_table::{layer_table, ModelSummary};
pub use network::activation::{Activation, OMEGA_0};
pub use network::design::{Design, TRANSPORT_CODE};
pub use network::encoder::{LightEncoder, LightInput, Texels};
pub use network::light_basis::{BasisChoice, LightBasis};
pub use network::light_entry::LightEntry;
pub use network::light_model::LightModel;
pub use network::mlp::Mlp;
pub use network::nprt_net::NprtNet;
pub use network::track::Track;
pub use network::track_kind::TrackKind;
pub use parameters::Parameters;
pub use precision::Precision;
pub use shading::{CpuEngine, NetworkEngine, Shading, UnetShading};
pub use training::batch::Batch;
pub use training::calibration::{level_gain, Calibration, LEVEL_SAMPLES};
pub use training::checkpoint::RunState;
pub use training::lr_schedule::LrSchedule;
pub use training::minutes::{check_minutes, MAX_MINUTES, MIN_MINUTES};
pub use training::nprt_objective::train;
pub use training::recipe::{Asked, Recipe, RECIPE};
pub use training::run_length::RunLength;
pub use training::schedule::Schedule;
pub use training::train_options::{recipe_rate, Gather, Targets, TrainOptions};
pub use training::training_loop::{Objective, TrainSummary, Watch};
pub use training::validation::validation_loss;
