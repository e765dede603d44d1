//! The light encoder's backward pass in a training step (a design's or the U-Net's): from the
//! gradient at the codes into every encoder weight, through the code layer and each block's
//! pool, ReLU and skip.

use crate::gpu::kernels::ENCODER_POOL_BACKWARD;
use crate::gpu::layers::conv::{
    conv_sums, record_input_gradient, record_weight_sums, Images, InputGradient,
};
use crate::gpu::layers::light_encoder::{BlockPass, EncoderAt};
use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::operands::{Bias, Operand, Output};
use crate::network::encoder::{CHANNELS, CODE_SIZE};
use nprt_gpu::{groups_for, Dispatch, GpuDevice};

impl EncoderAt {
    /// Appends to `plan` the encoder's backward pass over `views` maps from the gradient at
    /// their codes, `d_codes`, given what its forward pass kept (`tape`): every encoder
    /// weight's gradient into `grads`, its weights read from `params`.
    pub fn record_backward(
        &self,
        gpu: &GpuDevice,
        plan: &mut Vec<Dispatch>,
        [params, grads]: [&wgpu::Buffer; 2],
        views: usize,
        d_codes: &wgpu::Buffer,
        tape: &BlockPass,
    ) {
        let flat = self.to_code.d_in;
        plan.push(gpu.product(
            [flat, CODE_SIZE, views],
            Operand::transposed(&tape.last, 0, flat),
            Operand::plain(d_codes, 0, CODE_SIZE),
            Bias::None,
            0,
            Output::to(grads, self.to_code.weight.offset, CODE_SIZE),
            None,
        ));
        gpu.column_sum(
            plan,
            d_codes,
            views,
            CODE_SIZE,
            None,
            Output::to(grads, self.to_code.bias.offset, CODE_SIZE),
        );
        let mut d = gpu.buffer(views * flat);
        plan.push(gpu.product(
            [views, flat, CODE_SIZE],
            Operand::plain(d_codes, 0, CODE_SIZE),
            Operand::transposed(params, self.to_code.weight.offset, CODE_SIZE),
            Bias::None,
            0,
            Output::to(&d, 0, flat),
            None,
        ));
        let images = |k: usize| {
            let (h, w) = tape.sizes[k];
            Images { views, h, w }
        };
        let at: Vec<_> = (self.convs.iter().enumerate())
            .map(|(k, conv)| (conv, images(k)))
            .collect();
        // Every block's weight gradients summed per chunk into one set of blocks, added once.
        let sums = conv_sums(gpu, &at);
        for (k, conv) in self.convs.iter().enumerate().rev() {
            let images @ Images { h, w, .. } = images(k);
            let dz = gpu.buffer(images.values(CHANNELS));
            // The gradient at the block's input; block 0's input is the map, which needs none.
            let d_input = match k {
                0 => gpu.spare.clone(),
                _ => gpu.buffer(images.values(conv.c_in)),
            };
            let p = [conv.c_in, h, w, views, usize::from(k > 0), 0, 0, 0];
            plan.push(gpu.prepare(
                &ENCODER_POOL_BACKWARD,
                &p.map(|v| v as u32),
                &[&tape.tapes[k], &d, &dz, &d_input],
                groups_for(images.values(CHANNELS)),
            ));
            record_weight_sums(gpu, plan, (conv, &sums), images, &tape.inputs[k], &dz);
            if k > 0 {
                // Added to the skip's share, which the pool's backward wrote.
                let at = (conv, params);
                record_input_gradient(gpu, plan, at, images, &dz, &d_input, InputGradient::Add);
            }
            d = d_input;
        }
        sums.record_total(gpu, plan, grads, None);
    }
}
