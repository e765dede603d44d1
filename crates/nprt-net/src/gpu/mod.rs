//! Our own GPU kernels for the networks: WGSL compute shaders on nprt-gpu's device (wgpu:
//! Vulkan, Metal, DX12; Mesa's software Vulkan in the tests), computing what the CPU engine
//! ([`crate::cpu`]) computes, which tests hold them to. In layers, each folder using only those
//! before it (and nprt-gpu's runtime directly, never through this module):
//! 0. [`kernels`]: the kernel list, each shader's WGSL (`shaders/`, in folders by concept);
//! 1. `products`: matrix products and their operands, in f32 and on f16 (tensor cores),
//!    nprt-engine's;
//! 2. `layers`: where each tensor lies in the flat parameter buffer, and each layer's forward
//!    pass recorded on it;
//! 3. `passes`: backward passes and Adam on the device;
//! 4. `trainers` (each network's training step: [`GpuTrainer`], [`GpuUnet`], [`GpuCache`],
//!    with [`DeviceDataset`]) and, beside them, `frame` (a trained network's frames:
//!    [`GpuNetwork`], the GPU engine's [`crate::Shading`], made by [`GpuKernels`]).
//!
//! Layouts, designs and the hash grid stay defined where the CPU engine reads them
//! (`network`, `encoding`). The public surface is the trainers, the device network and the
//! kernel list, with the f16 weight layout the export writes.

mod frame;
pub mod kernels;
mod layers;
mod passes;
mod trainers;

// The matrix products, nprt-engine's, under the path the layers have always used.
use nprt_engine::gpu::products;

pub use frame::{DeviceShading, GpuKernels, GpuLightCode, GpuLightInput, GpuNetwork, GpuPixels};
pub use products::half_layers::{half_weight_bits, pad16};
pub use trainers::{DeviceDataset, GpuCache, GpuTrainer, GpuUnet};
