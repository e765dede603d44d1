//! The frame path's compute kernels: their WGSL sources, in the order a frame first uses them
//! (what `nprt export` writes), dispatched on nprt-net's GPU device.

use nprt_net::gpu::KernelSource;

/// Every kernel of the frame path, in the order a frame first uses them. The track inputs
/// (with the hash grid's encoding) and the encoder's blocks are nprt-net's, which training
/// shares.
pub const SOURCES: [&KernelSource; 5] = [
    &nprt_net::gpu::kernels::ENCODER_BLOCK,
    &nprt_net::gpu::kernels::TRACK_INPUTS,
    &KernelSource {
        name: "dense",
        wgsl: include_str!("shaders/dense.wgsl"),
    },
    &KernelSource {
        name: "code_bias",
        wgsl: include_str!("shaders/code_bias.wgsl"),
    },
    &KernelSource {
        name: "combine",
        wgsl: include_str!("shaders/combine.wgsl"),
    },
];

/// Which kernel a dispatch runs (an index into [`SOURCES`]).
#[derive(Clone, Copy)]
pub enum Kernel {
    EncoderBlock,
    TrackInputs,
    Dense,
    CodeBias,
    Combine,
}

impl Kernel {
    pub fn source(self) -> &'static KernelSource {
        SOURCES[self as usize]
    }
}

/// Rows and columns of the tile a `dense` workgroup computes.
pub const DENSE_TILE: u32 = 64;
