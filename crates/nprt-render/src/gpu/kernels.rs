//! The frame path's compute kernels: their WGSL sources, in the order a frame first uses them
//! (what `nprt export` writes), dispatched on nprt-net's GPU device. The track inputs (with the
//! hash grid's encoding), the encoder's blocks and the matrix product of every dense layer are
//! nprt-net's, which training shares; the combination into radiance is the frame's own.

use nprt_net::gpu::kernels::{ENCODER_BLOCK, GEMM, TRACK_INPUTS};
use nprt_net::gpu::KernelSource;

/// exp, kd/ks, Σ over tracks, × the map's scale.
pub const COMBINE: KernelSource = KernelSource {
    name: "combine",
    wgsl: include_str!("shaders/combine.wgsl"),
};

/// Every kernel of the frame path, in the order a frame first uses them.
pub const SOURCES: [&KernelSource; 4] = [&ENCODER_BLOCK, &TRACK_INPUTS, &GEMM, &COMBINE];
