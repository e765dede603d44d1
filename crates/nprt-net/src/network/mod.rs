//! The networks: the light encoder, dense layers and their activations, the transport tracks and
//! their kinds, the four designs, the whole network, and how their weights start.

pub mod activation;
pub mod design;
pub mod encoder;
pub mod mlp;
pub mod nprt_net;
pub mod track;
pub mod track_kind;
