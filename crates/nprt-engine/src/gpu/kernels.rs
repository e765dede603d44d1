//! The engine's kernels, by name: the matrix products (f32 with gemm's epilogues, and on f16
//! operands with tensor cores and without: a dense layer, a whole MLP, a training step's
//! forward, input-gradient and weight-gradient products, the weights' f16 copies), the chunks
//! of a split product added, convolutions and pools with their adjoints, and Adam. Each is its
//! file in `shaders/` (`products`, `convolutions`, `optimiser`) after the shared files it
//! names, by [`crate::kernel!`].

use nprt_gpu::KernelSource;

use crate::kernel;

pub const GEMM: KernelSource = kernel!(products / "gemm");
pub const COLUMN_SUM: KernelSource = kernel!(products / "column_sum");
pub const ADAM: KernelSource = kernel!(optimiser / "adam");
/// The frame path's half-precision dense layers (`half_layers`): the input's conversion, and
/// the product with tensor cores and without.
pub const HALF_ROWS: KernelSource = kernel!(products / "half_rows");
pub const HALF_DENSE: KernelSource = kernel!(products / "half_dense", products / "half_layer");
pub const HALF_DENSE_COOP: KernelSource = kernel!(
    products / "half_dense_coop",
    products / "coop_matrix",
    products / "half_layer",
    products / "coop_drain"
);
/// The frame path's whole MLP in half precision in one dispatch (`half_mlp`), without tensor
/// cores and with them.
pub const HALF_MLP_PLAIN: KernelSource =
    kernel!(products / "half_mlp_plain", products / "half_mlp");
pub const HALF_MLP_COOP: KernelSource = kernel!(
    products / "half_mlp_coop",
    products / "coop_matrix",
    products / "half_mlp",
    products / "coop_drain"
);
/// A mixed-precision training step's products (`half_products`): the dense layers' forward
/// and input-gradient products (the frame path's products under `half_train_layer`'s
/// epilogue), and the weight gradients, each with tensor cores and without.
pub const HALF_TRAIN: KernelSource =
    kernel!(products / "half_dense" as "half_train", products / "half_train_layer");
pub const HALF_TRAIN_COOP: KernelSource = kernel!(
    products / "half_dense_coop" as "half_train_coop",
    products / "coop_matrix",
    products / "half_train_layer",
    products / "coop_drain"
);
pub const HALF_WEIGHT_GRAD: KernelSource =
    kernel!(products / "half_weight_grad", products / "half_weight_sums");
/// A mixed-precision step's f16 copies of a weight, as stored and transposed, after Adam.
pub const HALF_WEIGHT_COPIES: KernelSource = kernel!(products / "half_weight_copies");
pub const HALF_WEIGHT_GRAD_COOP: KernelSource = kernel!(
    products / "half_weight_grad_coop",
    products / "coop_matrix",
    products / "half_weight_sums",
    products / "coop_drain"
);

/// Rows and columns of the tile a `gemm` workgroup computes.
pub const GEMM_TILE: u32 = 128;

/// Convolutional layers (nprt-net's U-Net and light encoder): convolutions, pools, the
/// U-Net's decoder inputs and bottleneck offsets, and their adjoints.
pub const CONV_FORWARD: KernelSource = kernel!(convolutions / "conv_forward");
pub const MAX_POOL: KernelSource = kernel!(convolutions / "max_pool");
pub const POOL_BACKWARD: KernelSource = kernel!(convolutions / "pool_backward");
pub const UPSAMPLE_CONCAT: KernelSource =
    kernel!(convolutions / "upsample_concat", convolutions / "upsample");
pub const UPSAMPLE_BACKWARD: KernelSource = kernel!(
    convolutions / "upsample_backward",
    convolutions / "upsample"
);
pub const PLANE_OFFSET: KernelSource = kernel!(convolutions / "plane_offset");
pub const OFFSET_BACKWARD: KernelSource = kernel!(convolutions / "offset_backward");
/// A convolution's gradients: at its input (the light encoder's and the U-Net's), and of its
/// weights and biases, per chunk of image rows.
pub const CONV_INPUT_BACKWARD: KernelSource = kernel!(convolutions / "conv_input_backward");
/// Threads `conv_input_backward` takes per input value: one per quarter of the channels.
pub const CONV_INPUT_BACKWARD_THREADS: usize = 4;
pub const CONV_WEIGHT_BACKWARD: KernelSource = kernel!(convolutions / "conv_weight_backward");
