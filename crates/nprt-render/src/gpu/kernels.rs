//! The frame path's compute kernels, in the order a frame first uses them (what `nprt export`
//! writes). They are nprt-net's network kernels, which training shares, dispatched on its GPU
//! device.

use nprt_gpu::KernelSource;
use nprt_net::gpu::kernels::{
    COMBINE, ENCODER_BLOCK, GEMM, HALF_DENSE, HALF_DENSE_COOP, HALF_ROWS, LIGHT_PROJECT,
    TRACK_INPUTS,
};

/// Every network kernel of the frame path, in the order a frame first uses them: what
/// `nprt export` writes (an engine brings its own G-buffer and background). A model runs the
/// encoder's or, for the linear design, the basis' projection.
pub fn sources() -> [&'static KernelSource; 5] {
    [
        &ENCODER_BLOCK,
        &LIGHT_PROJECT,
        &TRACK_INPUTS,
        &GEMM,
        &COMBINE,
    ]
}

/// The kernels `--precision f16` runs the transport networks' dense layers with instead of
/// `gemm`: the input made f16, and the product on tensor cores (cooperative matrices) or
/// without.
pub const HALF_SOURCES: [&KernelSource; 3] = [&HALF_ROWS, &HALF_DENSE, &HALF_DENSE_COOP];
