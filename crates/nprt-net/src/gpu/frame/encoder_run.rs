//! The light encoder on the frame path's device: its dispatches over inputs of one width
//! (`EncoderAt::record`: convolution blocks, each halving the image, then the dense
//! layer into the code, on the network's flat weights) kept for the next lighting of that
//! width.

use std::sync::Arc;

use crate::gpu::layers::network_layout::NetworkLayout;
use crate::network::encoder::CODE_SIZE;
use nprt_gpu::{Dispatch, GpuDevice, KeptLast};

use super::light_code::GpuLightCode;
use super::light_input::GpuLightInput;

/// The encoder's dispatches for inputs of the last width (its weights are the network's).
#[derive(Default)]
pub(super) struct GpuEncoder {
    runs: KeptLast<usize, Arc<EncoderRun>>,
}

/// The encoder's dispatches over inputs of one width, with the buffers they read and write.
pub(super) struct EncoderRun {
    /// The input a lighting's map is copied into (`3 × width/2 × width`).
    input: wgpu::Buffer,
    /// The code the last dispatch writes.
    code: wgpu::Buffer,
    dispatches: Vec<Dispatch>,
}

impl EncoderRun {
    pub fn dispatches(&self) -> &[Dispatch] {
        &self.dispatches
    }
}

impl GpuEncoder {
    /// The dispatches of the last width encoded, for profiling.
    pub fn kept(&self) -> Option<Arc<EncoderRun>> {
        self.runs.kept()
    }

    /// Records the encoder of `net` (its weights in `params`) over `input` (its dispatches
    /// kept per input width) into a new [`GpuLightCode`].
    pub fn record_code(
        &self,
        gpu: &GpuDevice,
        net: &NetworkLayout,
        params: &wgpu::Buffer,
        encoder: &mut wgpu::CommandEncoder,
        input: &GpuLightInput,
    ) -> GpuLightCode {
        let run = self.runs.get(input.width, || {
            let pixels = gpu.buffer(3 * input.width * (input.width / 2));
            let code = gpu.buffer(CODE_SIZE);
            let mut dispatches = Vec::new();
            let size = [1, input.width];
            net.encoder
                .record(gpu, &mut dispatches, params, &pixels, size, &code, false);
            Arc::new(EncoderRun {
                input: pixels,
                code,
                dispatches,
            })
        });
        let light = GpuLightCode::room(gpu);
        let code_bytes = 4 * CODE_SIZE as u64;
        encoder.copy_buffer_to_buffer(&input.pixels, 0, &run.input, 0, run.input.size());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            for d in &run.dispatches {
                d.record(&mut pass);
            }
        }
        encoder.copy_buffer_to_buffer(&run.code, 0, &light.buffer, 0, code_bytes);
        encoder.copy_buffer_to_buffer(&input.scale, 0, &light.buffer, code_bytes, 12);
        light
    }
}
