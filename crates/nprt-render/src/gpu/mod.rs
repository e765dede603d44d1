//! The GPU frame path: a trained model's light encoder and transport networks as WGSL compute
//! shaders over nprt-trace's rasterised G-buffer, the background and traced direct light
//! added, on nprt-gpu's device (Vulkan, Metal, DX12; Mesa's software Vulkan in the tests); and
//! the export of those shaders, translated to GLSL and HLSL, with the weights for engines.
//!
//! Owns the frame's own shaders (`shaders/`: the background and the encoder's input made from
//! the map), a model's upload and the order of dispatches of a frame. The network kernels and
//! the inputs made from a G-buffer are nprt-net's; the G-buffer, the scene on the device and the
//! path tracer nprt-trace's; the device nprt-gpu's. It computes what the CPU frame does
//! (nprt-net's CPU engine) in the same f32 operations, and tests hold them together; it must
//! not own semantics of its own: materials are nprt-scene's, layouts, designs and the hash grid
//! nprt-net's.

mod frame_background;
mod gpu_encoder;
mod gpu_network;
mod kernels;
mod light_code;
mod light_input;
mod shader_export;

pub use frame_background::{Background, Fill};
pub use gpu_network::{GpuNetwork, GpuPixels};
pub use light_code::GpuLightCode;
pub use light_input::GpuLightInput;
pub use shader_export::{export_model, ExportSummary};
