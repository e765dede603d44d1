//! What a renderer's own GPU stages need of a network on the GPU kernels, beyond what every
//! engine's [`Shading`] gives: the pixels of a G-buffer that stays on the device, and the
//! lighting-change work queued into a compute pass the renderer records into as well (its
//! background, from the map texels the encoder read). A renderer holds its stages to this
//! trait, never to the network's type.

use anyhow::Result;
use nprt_gpu::KernelTime;
use nprt_trace::gpu::GpuMap;

use super::gpu_pixels::GpuPixels;
use super::light_code::GpuLightCode;
use crate::shading::Shading;

/// A network on the GPU kernels, its light codes and pixels on the device.
pub trait DeviceShading: Shading<Code = GpuLightCode, Rows = GpuPixels> {
    /// The map texels this network's encoder inputs were last made from, which a renderer's
    /// background and traced light share.
    fn maps(&self) -> &GpuMap;

    /// [`Shading::pixels`] of every pixel of a G-buffer on the device (`pixels` samples of
    /// `RasterGBuffer::samples`), their inputs made there with the model's `bounds`; a
    /// background pixel's row runs too, on zero inputs, and the frame's background replaces
    /// it.
    fn pixels_of_gbuffer(
        &self,
        samples: &wgpu::Buffer,
        pixels: usize,
        bounds: &[[f32; 3]; 2],
    ) -> GpuPixels;

    /// The GPU time of each kernel of a lighting change on `px` under `code` (the last map's
    /// input and the encoder's at the last width, and what [`Shading::radiance`] runs before
    /// the background), each dispatch timed in a pass of its own: `nprt bench frame
    /// --profile`. An error where the adapter has no timestamp queries.
    fn profile_relight(&self, px: &GpuPixels, code: &GpuLightCode) -> Result<Vec<KernelTime>>;

    /// Queues [`Shading::radiance`]'s work into [`GpuPixels::rgb`], nothing waited for or read
    /// back, with `after` recorded into the same compute pass once the networks are done (a
    /// renderer's background, given the pass and the radiance buffer).
    fn queue_radiance(
        &self,
        px: &GpuPixels,
        code: &GpuLightCode,
        after: &mut dyn FnMut(&mut wgpu::ComputePass, &wgpu::Buffer),
    );
}
