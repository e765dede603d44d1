//! The light encoder's share of a training step: its blocks over the batch's maps keeping
//! their pooling tapes, the code layer, and backward from the gradient at the codes into every
//! encoder weight.

use super::gpu_trainer::{BatchBuffers, GpuTrainer};
use super::kernels::{
    ENCODER_INPUT_BACKWARD, ENCODER_INPUT_BACKWARD_THREADS, ENCODER_POOL_BACKWARD,
    ENCODER_WEIGHT_BACKWARD,
};
use super::network_layout::ConvAt;
use super::operands::{Bias, Operand, Output};
use super::products::DenseProducts;
use super::{groups_for, Dispatch};
use crate::network::encoder::{CHANNELS, CODE_SIZE};

/// Chunks of image rows a convolution's weight gradients are summed over, at most: enough
/// threads for a GPU (a 128 × 64 map's first block at 8 maps: 256 chunks × 896 values), and
/// few enough partial sums to add.
const CONV_CHUNKS: usize = 256;

/// What the encoder's forward pass keeps: each block's input, (h, w) and pooling tape, and
/// the last block's output (the flattened input of the code layer).
pub(super) struct EncoderTape {
    inputs: Vec<wgpu::Buffer>,
    sizes: Vec<(usize, usize)>,
    tapes: Vec<wgpu::Buffer>,
    flat: wgpu::Buffer,
}

impl GpuTrainer {
    /// Records the light encoder over the batch's maps: their codes into `b.codes`.
    pub(super) fn encoder_forward(
        &self,
        plan: &mut Vec<Dispatch>,
        b: &BatchBuffers,
    ) -> EncoderTape {
        let pass = self.net.record_encoder(
            &self.gpu,
            plan,
            &self.params,
            &b.lights,
            [b.views, b.light_width],
            &b.codes,
            true,
        );
        EncoderTape {
            inputs: pass.inputs,
            sizes: pass.sizes,
            tapes: pass.tapes,
            flat: pass.last,
        }
    }

    /// Records the light encoder's backward pass from the gradient at the codes, `b.d_codes`.
    pub(super) fn encoder_backward(
        &self,
        plan: &mut Vec<Dispatch>,
        b: &BatchBuffers,
        tape: &EncoderTape,
    ) {
        let gpu = &self.gpu;
        let flat = self.net.to_code.d_in;
        plan.push(self.gpu.product(
            [flat, CODE_SIZE, b.views],
            Operand::transposed(&tape.flat, 0, flat),
            Operand::plain(&b.d_codes, 0, CODE_SIZE),
            Bias::None,
            0,
            Output::to(&self.grads, self.net.to_code.weight.offset, CODE_SIZE),
            None,
        ));
        self.column_sum(
            plan,
            &b.d_codes,
            b.views,
            CODE_SIZE,
            None,
            Output::to(&self.grads, self.net.to_code.bias.offset, CODE_SIZE),
        );
        let mut d = gpu.buffer(b.views * flat);
        plan.push(self.gpu.product(
            [b.views, flat, CODE_SIZE],
            Operand::plain(&b.d_codes, 0, CODE_SIZE),
            Operand::transposed(&self.params, self.net.to_code.weight.offset, CODE_SIZE),
            Bias::None,
            0,
            Output::to(&d, 0, flat),
            None,
        ));
        for (k, conv) in self.net.convs.iter().enumerate().rev() {
            let (h, w) = tape.sizes[k];
            let count = b.views * CHANNELS * h * w;
            let dz = gpu.buffer(count);
            // The gradient at the block's input; block 0's input is the map, which needs none.
            let d_input = match k {
                0 => self.gpu.spare.clone(),
                _ => gpu.buffer(b.views * conv.c_in * h * w),
            };
            let params = [conv.c_in, h, w, b.views, usize::from(k > 0), 0, 0, 0];
            plan.push(gpu.prepare(
                &ENCODER_POOL_BACKWARD,
                &params.map(|v| v as u32),
                &[&tape.tapes[k], &d, &dz, &d_input],
                groups_for(count),
            ));
            self.conv_gradients(plan, conv, (h, w), b.views, &tape.inputs[k], &dz);
            if k > 0 {
                let params = [conv.c_in, h, w, b.views, conv.weight.offset, 0, 0, 0];
                plan.push(gpu.prepare(
                    &ENCODER_INPUT_BACKWARD,
                    &params.map(|v| v as u32),
                    &[&self.params, &dz, &d_input],
                    groups_for(ENCODER_INPUT_BACKWARD_THREADS * b.views * conv.c_in * h * w),
                ));
            }
            d = d_input;
        }
    }

    /// Records the gradients of a block's convolution weights and biases from its input and
    /// the gradient at its pre-activation `dz`: sums over chunks of image rows, then over the
    /// chunks in order.
    fn conv_gradients(
        &self,
        plan: &mut Vec<Dispatch>,
        conv: &ConvAt,
        (h, w): (usize, usize),
        views: usize,
        input: &wgpu::Buffer,
        dz: &wgpu::Buffer,
    ) {
        let rows = views * h;
        let chunk_rows = rows.div_ceil(CONV_CHUNKS);
        let chunks = rows.div_ceil(chunk_rows);
        let taps = conv.c_in * 9;
        let (weight_sums, bias_sums) = (
            self.gpu.buffer(chunks * CHANNELS * taps),
            self.gpu.buffer(chunks * CHANNELS),
        );
        let params = [conv.c_in, h, w, views, chunk_rows, chunks, 0, 0];
        plan.push(self.gpu.prepare(
            &ENCODER_WEIGHT_BACKWARD,
            &params.map(|v| v as u32),
            &[input, dz, &weight_sums, &bias_sums],
            groups_for(chunks * CHANNELS * (taps + 1)),
        ));
        let sums = [(&weight_sums, conv.weight), (&bias_sums, conv.bias)];
        for (partial, span) in sums {
            let n = span.len;
            self.column_sum(
                plan,
                partial,
                chunks,
                n,
                None,
                Output::to(&self.grads, span.offset, n),
            );
        }
    }
}
