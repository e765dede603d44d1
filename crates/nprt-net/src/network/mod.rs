//! The networks: the light encoder or basis, dense layers and their activations, the
//! transport tracks, their kinds and plans (the order every engine runs a track's networks in),
//! the designs, the whole network, the Deep Shading U-Net and the Neural Radiance Cache's
//! network, each of them `crate::parameters` to the model file and the optimiser.

pub mod design;
pub mod encoder;
pub mod light_basis;
pub mod light_entry;
pub mod light_model;
pub mod nprt_net;
pub mod radiance_cache;
pub mod track;
pub mod track_kind;
pub mod track_plan;
pub mod unet;

// The layers, nprt-engine's, under the paths the networks have always used.
pub use nprt_engine::layers::{activation, conv, dense, mlp};
