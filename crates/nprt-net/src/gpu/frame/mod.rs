//! A trained network's frames on the GPU kernels, beside its training step: the weights
//! uploaded once as a training step holds them, the light code made on the device from the map
//! (the encoder's input made there too), a camera's pixels run once through what does not
//! depend on the lighting, and each lighting through the shading networks and the combination
//! the training step records ([`GpuNetwork`], the [`crate::Shading`] of the GPU engine, which
//! [`GpuKernels`] makes). A renderer's own passes (a rasterised G-buffer's inputs, a
//! background, traced light) run beside these, into the same compute pass, through
//! [`DeviceShading`].

mod device_shading;
mod encoder_run;
mod gpu_network;
mod gpu_pixels;
mod light_code;
mod light_input;

pub use device_shading::DeviceShading;
pub use gpu_network::{GpuKernels, GpuNetwork};
pub use gpu_pixels::GpuPixels;
pub use light_code::GpuLightCode;
pub use light_input::GpuLightInput;
