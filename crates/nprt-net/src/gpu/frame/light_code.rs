//! A lighting on the device: what the encoder made of a map, left where the shading networks
//! read it, so that a lighting change on the GPU sends nothing back to the host.

use crate::network::encoder::CODE_SIZE;
use nprt_gpu::GpuDevice;

/// The light code ê (`CODE_SIZE` values) and the map's divisor per channel (3 values after
/// it) on the device.
#[derive(Clone)]
pub struct GpuLightCode {
    pub(super) buffer: wgpu::Buffer,
}

/// Values a [`GpuLightCode`] holds: the code, then the divisor.
pub(super) const LIGHT_CODE_VALUES: usize = CODE_SIZE + 3;

impl GpuLightCode {
    /// Room for a code the encoder kernels write.
    pub(super) fn room(gpu: &GpuDevice) -> Self {
        GpuLightCode {
            buffer: gpu.buffer(LIGHT_CODE_VALUES),
        }
    }

    /// A code and divisor made on the host (by the CPU engine, say), uploaded.
    pub fn upload(gpu: &GpuDevice, code: &[f32], divisor: [f32; 3]) -> Self {
        assert_eq!(code.len(), CODE_SIZE, "a light code has {CODE_SIZE} values");
        GpuLightCode {
            buffer: gpu.upload(&[code, &divisor].concat()),
        }
    }

    /// The code and the divisor, read back.
    pub fn read(&self, gpu: &GpuDevice) -> (Vec<f32>, [f32; 3]) {
        let mut code = gpu.read(&self.buffer, LIGHT_CODE_VALUES);
        let divisor = [code[CODE_SIZE], code[CODE_SIZE + 1], code[CODE_SIZE + 2]];
        code.truncate(CODE_SIZE);
        (code, divisor)
    }
}
