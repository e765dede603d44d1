//! A lighting on the device: what the light model made of a map, left where the shading
//! networks read it, so that a lighting change on the GPU sends nothing back to the host.

use nprt_gpu::GpuDevice;

/// The light code (the encoder's ê, or the linear design's projection e: `values` of them)
/// and the map's divisor per channel (3 values after it) on the device.
#[derive(Clone)]
pub struct GpuLightCode {
    pub(super) buffer: wgpu::Buffer,
    /// The code's values, the divisor not counted.
    pub(super) values: usize,
}

impl GpuLightCode {
    /// Room for a code of `values` values that the light model's kernels write.
    pub(super) fn room(gpu: &GpuDevice, values: usize) -> Self {
        GpuLightCode {
            buffer: gpu.buffer(values + 3),
            values,
        }
    }

    /// A code and divisor made on the host (by the CPU engine, say), uploaded.
    pub fn upload(gpu: &GpuDevice, code: &[f32], divisor: [f32; 3]) -> Self {
        GpuLightCode {
            buffer: gpu.upload(&[code, &divisor].concat()),
            values: code.len(),
        }
    }

    /// The code and the divisor, read back.
    pub fn read(&self, gpu: &GpuDevice) -> (Vec<f32>, [f32; 3]) {
        let mut code = gpu.read(&self.buffer, self.values + 3);
        let divisor = std::array::from_fn(|k| code[self.values + k]);
        code.truncate(self.values);
        (code, divisor)
    }
}
