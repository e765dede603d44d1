//! The network kernels nprt-net owns: the light encoder's blocks and the track inputs (with the
//! hash grid's encoding), which the frame path dispatches too, and the training step's.

use super::KernelSource;

pub const ENCODER_BLOCK: KernelSource = KernelSource {
    name: "encoder_block",
    wgsl: include_str!("shaders/encoder_block.wgsl"),
};

pub const ENCODER_POOL_BACKWARD: KernelSource = KernelSource {
    name: "encoder_pool_backward",
    wgsl: include_str!("shaders/encoder_pool_backward.wgsl"),
};

pub const ENCODER_WEIGHT_BACKWARD: KernelSource = KernelSource {
    name: "encoder_weight_backward",
    wgsl: include_str!("shaders/encoder_weight_backward.wgsl"),
};

pub const ENCODER_INPUT_BACKWARD: KernelSource = KernelSource {
    name: "encoder_input_backward",
    wgsl: include_str!("shaders/encoder_input_backward.wgsl"),
};

pub const TRACK_INPUTS: KernelSource = KernelSource {
    name: "track_inputs",
    wgsl: concat!(
        include_str!("shaders/hash_grid.wgsl"),
        include_str!("shaders/track_inputs.wgsl")
    ),
};

pub const GEMM: KernelSource = KernelSource {
    name: "gemm",
    wgsl: include_str!("shaders/gemm.wgsl"),
};

pub const COLUMN_SUM: KernelSource = KernelSource {
    name: "column_sum",
    wgsl: include_str!("shaders/column_sum.wgsl"),
};

pub const ACTIVATION_BACKWARD: KernelSource = KernelSource {
    name: "activation_backward",
    wgsl: include_str!("shaders/activation_backward.wgsl"),
};

pub const RADIANCE_LOSS: KernelSource = KernelSource {
    name: "radiance_loss",
    wgsl: include_str!("shaders/radiance_loss.wgsl"),
};

pub const GRID_BACKWARD: KernelSource = KernelSource {
    name: "grid_backward",
    wgsl: concat!(
        include_str!("shaders/hash_grid.wgsl"),
        include_str!("shaders/grid_backward.wgsl")
    ),
};

pub const ADAM: KernelSource = KernelSource {
    name: "adam",
    wgsl: include_str!("shaders/adam.wgsl"),
};

/// Rows and columns of the tile a `gemm` workgroup computes.
pub const GEMM_TILE: u32 = 64;
