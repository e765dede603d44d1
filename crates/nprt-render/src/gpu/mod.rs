//! The GPU frame path: a trained model's light encoder and transport networks as WGSL compute
//! shaders on wgpu (Vulkan, Metal, DX12; Mesa's software Vulkan in the tests), and the export
//! of those shaders, translated to GLSL and HLSL, with the weights for engines.
//!
//! Owns the frame's kernels (`shaders/`; the device they run on is nprt-net's), the upload of a model's weights and the order of dispatches
//! of a frame. It computes what the CPU engine (nprt-net's `cpu`) computes, in the same f32
//! operations, and a test holds the two together; it must not own network semantics of its
//! own: layouts, designs and the hash grid are nprt-net's, read from there.

mod gpu_network;
mod kernels;
mod shader_export;

pub use gpu_network::{GpuNetwork, GpuPixels};
pub use nprt_net::gpu::GpuDevice;
pub use shader_export::{export_model, ExampleView, ExportSummary};
