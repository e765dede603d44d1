//! Layers on the device that are not a design's own, on the products below them: where a dense
//! layer's or a convolution's tensors lie in a network's flat parameter buffer (`layer_at`),
//! convolutions with the gradients at their inputs and weights (`conv`, the CPU's
//! `cpu/conv.rs`), and gradients summed per chunk of rows into a span of the parameters
//! (`chunk_sums`), which the convolutions' weights and a mixed-precision MLP step share.
//! nprt-net's networks (the light encoder, the U-Net, the tracks) record them.

pub mod chunk_sums;
pub mod conv;
pub mod layer_at;
