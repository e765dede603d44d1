//! Our own GPU kernels: WGSL compute shaders on wgpu (Vulkan, Metal, DX12; Mesa's software
//! Vulkan in the tests). This module owns the device (one per process), how a kernel is
//! compiled and dispatched, storage buffers, the training step of every design on the device
//! ([`GpuTrainer`]) and the training set held there ([`DeviceDataset`]). nprt-render's frame
//! path dispatches these kernels and its own on the same device. The kernels compute what the
//! CPU engine ([`crate::cpu`]) computes, in f32 (the frame path and training may also run the
//! transport networks' dense layers on f16 operands: [`HalfWeight`], `half_products`), and
//! tests hold the two together; layouts, designs and the hash grid stay defined where the CPU
//! engine reads them.

mod buffer_pool;
mod codes;
mod device_dataset;
mod encoder_blocks;
mod encoder_step;
mod gpu_buffer;
mod gpu_device;
mod gpu_trainer;
mod half_layers;
mod half_products;
mod kernel;
mod kernel_timer;
pub mod kernels;
mod network_layout;
mod parameters;
mod products;
mod transport_step;

pub use buffer_pool::{BufferPool, PooledBuffer};
pub use codes::{activation_code, loss_code};
pub use device_dataset::DeviceDataset;
pub use encoder_blocks::{record_blocks, BlockPass, BlockWeights};
pub use gpu_device::GpuDevice;
pub use gpu_trainer::GpuTrainer;
pub use half_layers::{half_weight_bits, held_halves, pad16, HalfWeight, Held, HALF_ROW_BLOCK};
pub use kernel::{groups_for, Bind, Dispatch, KernelSource, Part, GROUP};
pub use kernel_timer::KernelTime;
pub use parameters::{ParameterLayout, Span};
pub use products::{Bias, Operand, Output};
