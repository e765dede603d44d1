//! nprt-engine: the arithmetic every network of nprt runs on, below the designs and their
//! training, as candle-core and tiny-cuda-nn are below a model: the layers' parameters and
//! their initialisation (dense, MLP, convolution, activations), the losses, Adam and its state
//! file, the named choices' parsing, and their CPU kernels (blocked matrix products through
//! gemm, fused bias and activation passes, vectorised sin/cos, convolutions as products,
//! pooling); with the `gpu` feature, the matrix products on the device (f32 and f16, on tensor
//! cores where the adapter has them), the convolutions and pools with their adjoints, where a
//! layer's tensors lie in a flat parameter buffer, and their WGSL. It must not know a design, a track, a
//! light model, a dataset or a frame: nprt-net builds those on it.

pub mod choice;
pub mod cpu;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod init;
pub mod layers;
pub mod loss;
pub mod optimiser;
pub mod parameters;
pub mod precision;
