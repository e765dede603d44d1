//! Our own GPU kernels for the networks: WGSL compute shaders on nprt-gpu's device (wgpu:
//! Vulkan, Metal, DX12; Mesa's software Vulkan in the tests). This module owns the network
//! kernels and how their dispatches are recorded: the light encoder's blocks, the dense layers'
//! products (in f32, and on f16 operands: [`HalfWeight`], `half_products`), the training step of
//! every design on the device ([`GpuTrainer`]), the training set held there
//! ([`DeviceDataset`]) and a trained network's frames (`frame`: [`GpuNetwork`]). The kernels
//! compute what the CPU engine ([`crate::cpu`]) computes, and tests hold the two together;
//! layouts, designs and the hash grid stay defined where the CPU engine reads them.

mod codes;
mod conv_layers;
mod dense_products;
mod device_adam;
mod device_dataset;
mod encoder_blocks;
mod encoder_step;
mod frame;
mod gpu_trainer;
mod half_layers;
mod half_products;
pub mod kernels;
mod layer_at;
mod mlp_step;
mod network_forward;
mod network_layout;
mod operands;
mod parameters;
mod plans;
mod radiance_cache;
mod transport_step;
mod unet_pass;
mod unet_trainer;

pub use codes::{activation_code, loss_code};
pub use dense_products::DenseProducts;
pub use device_dataset::DeviceDataset;
pub use encoder_blocks::{BlockPass, EncoderAt};
pub use frame::{GpuLightCode, GpuLightInput, GpuNetwork, GpuPixels};
pub use gpu_trainer::GpuTrainer;
pub use half_layers::{
    half_weight_bits, held_halves, pad16, HalfLayers, HalfWeight, Held, HALF_ROW_BLOCK,
};
pub use layer_at::{ConvAt, DenseAt};
pub use network_forward::{FirstLayer, ForwardTargets};
pub use network_layout::{HalfCopies, MlpAt, NetworkLayout, TrackAt};
pub use operands::{Bias, Operand, Output};
pub use parameters::ParameterLayout;
pub use radiance_cache::GpuCache;
pub use unet_trainer::GpuUnet;

// The runtime the kernels run on (nprt-gpu), as this module's files name it.
use nprt_gpu::{groups_for, Bind, Dispatch, GpuDevice, KernelSource, Part, Span};
