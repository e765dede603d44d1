//! The GPU frame path's own stages and the export: a frame's G-buffer rasterised by
//! nprt-trace and left on the device, the background and traced direct light recorded beside
//! nprt-net's networks on the GPU kernels (a `nprt_net::gpu::DeviceShading`, which runs the
//! encoder and the transport networks), on nprt-gpu's device (Vulkan, Metal, DX12; Mesa's
//! software Vulkan in the tests); and the export of the networks' shaders, translated to GLSL and HLSL, with the
//! weights for engines.
//!
//! Owns the frame's background shader (`shaders/`) and the order of a frame's stages on the
//! device ([`DeviceStages`]). The networks, their kernels and the inputs made from a G-buffer
//! are nprt-net's; the G-buffer, the scene on the device and the path tracer nprt-trace's; the
//! device nprt-gpu's. It must not own semantics of its own: materials are nprt-scene's,
//! layouts, designs and the hash grid nprt-net's.

mod device_stages;
mod frame_background;
mod kernels;
mod shader_export;

pub use device_stages::DeviceStages;
pub use shader_export::{export_model, ExportSummary};
