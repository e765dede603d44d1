//! The light model on the frame path's device: its dispatches over inputs of one width kept
//! for the next lighting of that width: the encoder's (`EncoderAt::record`: convolution
//! blocks, each halving the image, then the dense layer into the code, on the network's flat
//! weights) or the linear design's projection on its basis (`light_project`).

use std::sync::Arc;

use crate::gpu::layers::network_layout::{LightAt, NetworkLayout};
use nprt_gpu::{Dispatch, GpuDevice, KeptLast};

use super::light_code::GpuLightCode;
use super::light_input::GpuLightInput;

/// The light model's dispatches for inputs of the last width (its weights are the network's).
#[derive(Default)]
pub(super) struct GpuEncoder {
    runs: KeptLast<usize, Arc<EncoderRun>>,
}

/// The light model's dispatches over inputs of one width, with the buffers they read and
/// write.
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

    /// Records the light model of `net` (its weights in `params`) over `input` (its
    /// dispatches kept per input width) into a new [`GpuLightCode`].
    pub fn record_code(
        &self,
        gpu: &GpuDevice,
        net: &NetworkLayout,
        params: &wgpu::Buffer,
        encoder: &mut wgpu::CommandEncoder,
        input: &GpuLightInput,
    ) -> GpuLightCode {
        let run = self.runs.get(input.width, || {
            let texels = input.width * (input.width / 2);
            let pixels = gpu.buffer(3 * texels);
            let code = gpu.buffer(net.light.code_size());
            let mut dispatches = Vec::new();
            match &net.light {
                LightAt::Encoder(e) => {
                    let size = [1, input.width];
                    e.record(gpu, &mut dispatches, params, &pixels, size, &code, false);
                }
                LightAt::Basis(b) => {
                    assert_eq!(b.texels, texels, "the basis' map width");
                    dispatches.push(b.record_project(gpu, params, &pixels, 1, &code));
                }
            }
            Arc::new(EncoderRun {
                input: pixels,
                code,
                dispatches,
            })
        });
        let light = GpuLightCode::room(gpu, net.light.code_size());
        let code_bytes = 4 * light.values as u64;
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
