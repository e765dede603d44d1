//! Where each tensor of a network lies in the flat parameter buffer (`parameters`,
//! `network_layout`: encoder blocks, tracks, layers and their f16 copies; a layer's own place,
//! `layer_at`, is nprt-engine's) and how each layer's forward pass is recorded on it: the light
//! encoder's convolution blocks (`light_encoder`, the CPU's `cpu/light_encoder.rs`) or the
//! linear design's basis (`light_basis`, `cpu/light_model.rs`), the convolutions (`conv`, with
//! their weights' sums over chunks of rows, `chunk_sums`: nprt-engine's), a track's inputs and
//! an MLP in f32 or f16 (`network_forward`, the forward
//! half of `cpu/transport.rs` and `cpu/dense.rs`) with what a training step keeps of it
//! (`mlp_tape`). Uses `products` below it.

// nprt-engine's layers, under the paths the networks have always used.
pub(crate) use nprt_engine::gpu::layers::{chunk_sums, conv, layer_at};
pub(crate) mod light_basis;
pub(crate) mod light_encoder;
pub(crate) mod mlp_tape;
pub(crate) mod network_forward;
pub(crate) mod network_layout;
pub(crate) mod parameters;
