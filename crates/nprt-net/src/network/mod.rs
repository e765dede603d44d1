//! The networks: the light encoder, dense layers and their activations, the transport tracks and
//! their kinds, the four designs, the whole network, and how their weights start.

pub mod activation;
pub mod design;
pub mod encoder;
pub mod init;
pub mod mlp;
pub mod nprt_net;
pub mod track;
pub mod track_kind;

/// A tensor's values as f32 on the host.
pub fn host_values(data: burn::tensor::TensorData) -> Vec<f32> {
    data.convert::<f32>()
        .try_into_vec::<f32>()
        .expect("converted to f32")
}
