//! The GPU frame path: the scene rasterised into the G-buffer, a trained model's light encoder
//! and transport networks as WGSL compute shaders, and the scene path traced in one, on wgpu
//! (Vulkan, Metal, DX12; Mesa's software Vulkan in the tests); and the export of those shaders,
//! translated to GLSL and HLSL, with the weights for engines.
//!
//! Owns the frame's shaders (`shaders/`: the visibility pass, the G-buffer it resolves, the
//! background and the encoder's input made from the map, and the path tracer: a BVH walk, the
//! BSDFs and the map's importance sampling, for traced direct light and the viewer's
//! reference; the network kernels, the inputs made from a G-buffer and the device they run on
//! are nprt-net's), the scene's and a model's
//! upload and the order of dispatches of a frame. It computes what the CPU does (nprt-trace's
//! G-buffer and paths, nprt-net's CPU engine) in the same f32 operations (paths with random
//! numbers of their own), and tests hold them together;
//! it must not own semantics of its own: materials are nprt-scene's, layouts, designs and the
//! hash grid nprt-net's.

mod frame_background;
mod gpu_encoder;
mod gpu_map;
mod gpu_mlp;
mod gpu_network;
mod gpu_scene;
mod kept_last;
mod kernels;
mod light_code;
mod light_input;
mod path_tracer;
mod raster_gbuffer;
mod shader_export;

pub use frame_background::{Background, Fill};
pub use gpu_network::{GpuNetwork, GpuPixels};
pub(crate) use kept_last::KeptLast;
pub use light_code::GpuLightCode;
pub use light_input::GpuLightInput;
pub use nprt_net::gpu::GpuDevice;
pub use path_tracer::GpuPaths;
pub use raster_gbuffer::RasterGBuffer;
pub use shader_export::{export_model, ExampleView, ExportSummary};
