//! The trainers, top of the training side: each network's whole step on the device, its
//! recorded passes kept per batch shape (`plans`). [`GpuTrainer`] steps the NPRT designs (its
//! transport forward, loss and backward in `transport`, the CPU's `cpu/transport.rs`) on a
//! training set held on the device ([`DeviceDataset`]); [`GpuUnet`] the Deep Shading U-Net
//! (`cpu/unet.rs`); [`GpuCache`] the radiance cache trained online (`cpu/radiance_cache.rs`).
//! Uses `passes`, `layers` and `products` below it; `frame` beside it uses none of it.

pub(crate) mod device_dataset;
pub(crate) mod gpu_trainer;
pub(crate) mod plans;
pub(crate) mod radiance_cache;
pub(crate) mod transport;
pub(crate) mod unet;

pub use device_dataset::DeviceDataset;
pub use gpu_trainer::GpuTrainer;
pub use radiance_cache::GpuCache;
pub use unet::GpuUnet;
