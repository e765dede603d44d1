//! The light encoder on the frame path's device: its weights uploaded once, and its dispatches
//! over inputs of one width (convolution blocks, each halving the image, then the dense layer
//! into the code) kept for the next lighting of that width.

use std::sync::Arc;

use nprt_gpu::{Dispatch, GpuDevice};
use nprt_net::gpu::{record_blocks, BlockWeights};
use nprt_net::network::encoder::{BLOCKS, CODE_SIZE};
use nprt_net::LightEncoder;

use super::gpu_mlp::{dense_layer, GpuDense, Rows};
use super::light_code::GpuLightCode;
use super::light_input::GpuLightInput;
use nprt_gpu::KeptLast;

/// The encoder's weights on the device and its dispatches for inputs of the last width.
pub(super) struct GpuEncoder {
    /// Each convolution block's weight, bias and input channels.
    convs: Vec<(wgpu::Buffer, wgpu::Buffer, usize)>,
    /// The dense layer into the code.
    to_code: GpuDense,
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
    /// `encoder`'s weights uploaded.
    pub fn upload(gpu: &GpuDevice, encoder: &LightEncoder) -> Self {
        GpuEncoder {
            convs: encoder
                .convs
                .iter()
                .map(|c| (gpu.upload(&c.weight), gpu.upload(&c.bias), c.c_in))
                .collect(),
            to_code: GpuDense::upload(gpu, &encoder.to_code),
            runs: KeptLast::default(),
        }
    }

    /// The dispatches of the last width encoded, for profiling.
    pub fn kept(&self) -> Option<Arc<EncoderRun>> {
        self.runs.kept()
    }

    /// Records the encoder over `input` (its dispatches kept per input width) into a new
    /// [`GpuLightCode`].
    pub fn record_code(
        &self,
        gpu: &GpuDevice,
        encoder: &mut wgpu::CommandEncoder,
        input: &GpuLightInput,
    ) -> GpuLightCode {
        let run = self
            .runs
            .get(input.width, || Arc::new(self.run(gpu, input.width)));
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

    /// The encoder's dispatches over inputs `width` wide.
    fn run(&self, gpu: &GpuDevice, width: usize) -> EncoderRun {
        let input = gpu.buffer(3 * width * (width / 2));
        let code = gpu.buffer(CODE_SIZE);
        let blocks: Vec<BlockWeights> = (self.convs.iter())
            .map(|(weight, bias, c_in)| BlockWeights {
                weight,
                bias,
                c_in: *c_in,
            })
            .collect();
        debug_assert_eq!(blocks.len(), BLOCKS);
        let mut dispatches = Vec::new();
        let x = record_blocks(gpu, &mut dispatches, &input, [1, width], &blocks, false).last;
        let flat = Rows {
            x: &x,
            rows: 1,
            d_in: self.to_code.d_in,
            w_row: 0,
        };
        let to_code = &self.to_code;
        dispatches.push(dense_layer(gpu, to_code, flat, &to_code.bias, 0, &code));
        EncoderRun {
            input,
            code,
            dispatches,
        }
    }
}
