//! Where each tensor of a network lies in the flat parameter buffer (`parameters`,
//! `layer_at`, `network_layout`: encoder blocks, tracks, layers and their f16 copies) and how
//! each layer's forward pass is recorded on it: the light encoder's convolution blocks
//! (`light_encoder`, the CPU's `cpu/light_encoder.rs`) or the linear design's basis
//! (`light_basis`, `cpu/light_model.rs`), the U-Net's convolutions (`conv`,
//! `cpu/conv.rs`; their weights' sums over chunks of rows in `chunk_sums`), a track's inputs and an MLP in f32 or f16 (`network_forward`, the forward
//! half of `cpu/transport.rs` and `cpu/dense.rs`) with what a training step keeps of it
//! (`mlp_tape`). Uses `products` below it.

pub(crate) mod chunk_sums;
pub(crate) mod conv;
pub(crate) mod layer_at;
pub(crate) mod light_basis;
pub(crate) mod light_encoder;
pub(crate) mod mlp_tape;
pub(crate) mod network_forward;
pub(crate) mod network_layout;
pub(crate) mod parameters;
