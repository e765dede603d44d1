//! The lowest layer of the GPU kernels: matrix products and their operands, in f32
//! (`dense_products`, gemm's epilogues) and on f16 operands (`half_layers`: the f16 weight
//! layout, rows padded to 16, and the product on tensor cores where the adapter has them;
//! `half_mlp`: a whole MLP's forward pass in one dispatch), with
//! the codes the shaders read for activations and losses. The CPU engine's twin is
//! `cpu/matmul.rs`. Uses only the kernel list and nprt-gpu's runtime.

pub mod codes;
pub mod dense_products;
pub mod half_layers;
pub mod half_mlp;
pub mod operands;
