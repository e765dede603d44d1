//! The Deep Shading U-Net on the device: where its tensors lie in the flat buffers, and its
//! training pass recorded once per batch shape: the light encoder and the code's bottleneck
//! offsets, the encoder levels (two convolutions and a pool each), the bottleneck, the decoder
//! levels (up-sampling joined with the level's skip, one convolution), the output convolution,
//! the masked loss; then backward into every weight's gradient. It computes what the CPU
//! engine's `cpu::unet` computes, in f32, and the tests hold the two together.

use crate::encoding::features::FEATURES;
use crate::gpu::kernels::{
    MAX_POOL, OFFSET_BACKWARD, PLANE_OFFSET, POOL_BACKWARD, UNET_LOSS, UPSAMPLE_BACKWARD,
    UPSAMPLE_CONCAT,
};
use crate::gpu::layers::conv::{
    record_conv, record_input_gradient, record_weight_gradients, Images, InputGradient,
};
use crate::gpu::layers::layer_at::{ConvAt, DenseAt};
use crate::gpu::layers::light_encoder::{BlockPass, EncoderAt};
use crate::gpu::layers::parameters::ParameterLayout;
use crate::gpu::products::codes::loss_code;
use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::operands::{Bias, Operand, Output};
use crate::loss::Loss;
use crate::network::encoder::CODE_SIZE;
use crate::network::unet::{DeepShading, LEVELS};
use nprt_gpu::{groups_for, Dispatch, GpuDevice};

/// The U-Net's tensors in the flat buffers.
pub struct UnetAt {
    encoder: EncoderAt,
    /// Every convolution in the order the forward pass runs them: the encoder levels' two
    /// each, the bottleneck's two, the decoder's one per level, the output's.
    convs: Vec<ConvAt>,
    code: DenseAt,
}

/// Index in [`UnetAt::convs`] of the bottleneck's first convolution, the decoder's first and
/// the output's.
const BOTTLENECK: usize = 2 * LEVELS;
const DECODER: usize = BOTTLENECK + 2;
const OUT: usize = DECODER + LEVELS;

/// A batch of whole views on the device, what the pass computes from it, and its shape.
pub struct UnetBuffers {
    pub images: Images,
    pub light_width: usize,
    pub features: wgpu::Buffer,
    pub radiance: wgpu::Buffer,
    pub mask: wgpu::Buffer,
    pub lights: wgpu::Buffer,
    pub scale: wgpu::Buffer,
    pub prediction: wgpu::Buffer,
    /// The masked loss summed over the batch (one value).
    pub loss: wgpu::Buffer,
    codes: wgpu::Buffer,
    d_codes: wgpu::Buffer,
    offsets: wgpu::Buffer,
    d_offsets: wgpu::Buffer,
    d_y: wgpu::Buffer,
    values: wgpu::Buffer,
}

impl UnetBuffers {
    pub fn new(gpu: &GpuDevice, images: Images, light_width: usize, width: usize) -> Self {
        let (views, hw) = (images.views, images.h * images.w);
        UnetBuffers {
            images,
            light_width,
            features: gpu.buffer(images.values(FEATURES)),
            radiance: gpu.buffer(images.values(3)),
            mask: gpu.buffer(views * hw),
            lights: gpu.buffer(views * 3 * light_width * light_width / 2),
            scale: gpu.buffer(views * 3),
            prediction: gpu.buffer(images.values(3)),
            loss: gpu.buffer(1),
            codes: gpu.buffer(views * CODE_SIZE),
            d_codes: gpu.buffer(views * CODE_SIZE),
            offsets: gpu.buffer(views * width),
            d_offsets: gpu.buffer(views * width),
            d_y: gpu.buffer(images.values(3)),
            values: gpu.buffer(images.values(3)),
        }
    }
}

/// What the forward pass keeps for backward: each convolution's input and output, each
/// encoder level's pooling choices, each decoder level's joined input, and the light
/// encoder's tape.
pub struct UnetTape {
    inputs: Vec<wgpu::Buffer>,
    outputs: Vec<wgpu::Buffer>,
    taken: Vec<wgpu::Buffer>,
    encoder: BlockPass,
}

/// The parameter block of `unet_loss` for a batch whose foreground pixels are `foreground`.
pub fn loss_params(images: Images, loss: Loss, foreground: f64) -> Vec<u32> {
    let norm = 1.0 / (3.0 * foreground).max(1.0) as f32;
    let hw = images.h * images.w;
    let mut p = vec![images.views as u32, hw as u32, loss_code(loss), 0];
    p.extend([norm, 0.0, 0.0, 0.0].map(f32::to_bits));
    p
}

impl UnetAt {
    /// `net`'s places in `layout` (packed from a network of its shapes).
    pub fn new(net: &DeepShading, layout: &ParameterLayout) -> Self {
        // Spans in the order the network visits its tensors (`DeepShading::visit`).
        let mut spans = layout.spans.iter().copied();
        let encoder = EncoderAt::new(&net.light, &mut spans);
        let mut conv_at = |c| ConvAt::new(c, &mut spans);
        let mut convs: Vec<ConvAt> = net
            .down
            .iter()
            .chain(&net.bottleneck)
            .map(&mut conv_at)
            .collect();
        let code = DenseAt::new(&net.code, &mut spans);
        let mut conv_at = |c| ConvAt::new(c, &mut spans);
        convs.extend(net.up.iter().chain([&net.out]).map(&mut conv_at));
        assert!(spans.next().is_none(), "a tensor without a place");
        UnetAt {
            encoder,
            convs,
            code,
        }
    }

    /// Values per view of the bottleneck offset.
    pub fn offset_width(&self) -> usize {
        self.code.d_out
    }

    /// Appends to `plan` the forward pass over `b` through the masked `loss` (its sum into
    /// `b.loss`, the prediction into `b.prediction`, the gradient at the output convolution
    /// kept for backward), weights in `params`. Returns the tape and the index in `plan` of the
    /// loss's dispatch, whose parameters ([`loss_params`]) change with each batch's foreground.
    pub fn record_forward(
        &self,
        gpu: &GpuDevice,
        plan: &mut Vec<Dispatch>,
        params: &wgpu::Buffer,
        b: &UnetBuffers,
        loss: Loss,
    ) -> (UnetTape, usize) {
        let views = b.images.views;
        let maps = [views, b.light_width];
        let encoder = self
            .encoder
            .record(gpu, plan, params, &b.lights, maps, &b.codes, true);
        let width = self.code.d_out;
        plan.push(gpu.product(
            [views, width, CODE_SIZE],
            Operand::plain(&b.codes, 0, CODE_SIZE),
            Operand::plain(params, self.code.weight.offset, width),
            Bias::Column(params, self.code.bias.offset),
            0,
            Output::to(&b.offsets, 0, width),
            None,
        ));
        let mut tape = UnetTape {
            inputs: Vec::new(),
            outputs: Vec::new(),
            taken: Vec::new(),
            encoder,
        };
        let conv = |plan: &mut Vec<Dispatch>, tape: &mut UnetTape, x: wgpu::Buffer, images| {
            let at = &self.convs[tape.inputs.len()];
            let out = gpu.buffer(Images::values(images, at.c_out));
            let relu = tape.inputs.len() != OUT;
            record_conv(gpu, plan, (at, params), images, &x, &out, relu);
            tape.inputs.push(x);
            tape.outputs.push(out.clone());
            out
        };
        let mut images = b.images;
        let mut x = b.features.clone();
        for _ in 0..LEVELS {
            let a = conv(plan, &mut tape, x, images);
            let skip = conv(plan, &mut tape, a, images);
            let c = self.convs[tape.inputs.len() - 1].c_out;
            let (pooled, taken, half) = record_pool(gpu, plan, &skip, images, c);
            tape.taken.push(taken);
            (x, images) = (pooled, half);
        }
        // The code's offsets are added after the first bottleneck convolution's ReLU.
        let a = conv(plan, &mut tape, x, images);
        let shifted = gpu.buffer(images.values(width));
        let hw = images.h * images.w;
        plan.push(gpu.prepare(
            &PLANE_OFFSET,
            &[views * width, hw, 0, 0].map(|v| v as u32),
            &[&a, &b.offsets, &shifted],
            groups_for(images.values(width)),
        ));
        x = conv(plan, &mut tape, shifted, images);
        for u in 0..LEVELS {
            let skip = tape.outputs[2 * (LEVELS - 1 - u) + 1].clone();
            let channels = [
                self.convs[DECODER + u - 1].c_out,
                self.convs[DECODER + u].c_in,
            ];
            let (joined, full) = record_join(gpu, plan, [&x, &skip], images, channels);
            images = full;
            x = conv(plan, &mut tape, joined, images);
        }
        let y = conv(plan, &mut tape, x, images);
        let loss_at = record_loss(gpu, plan, &y, b, images, loss);
        (tape, loss_at)
    }

    /// Appends to `plan` the backward pass from the loss's gradient that
    /// [`Self::record_forward`] left in `b`: every weight's gradient into `grads`.
    pub fn record_backward(
        &self,
        gpu: &GpuDevice,
        plan: &mut Vec<Dispatch>,
        [params, grads]: [&wgpu::Buffer; 2],
        b: &UnetBuffers,
        tape: &UnetTape,
    ) {
        let views = b.images.views;
        let conv = |i: usize| (&self.convs[i], params);
        let weights = |plan: &mut Vec<Dispatch>, i: usize, images, dz: &wgpu::Buffer| {
            record_weight_gradients(
                gpu,
                plan,
                (&self.convs[i], grads),
                images,
                &tape.inputs[i],
                dz,
            );
        };
        // The gradient at a convolution's input, passed through the ReLU that made it.
        let through = |plan: &mut Vec<Dispatch>, i: usize, images, dz: &wgpu::Buffer| {
            let d = gpu.buffer(Images::values(images, self.convs[i].c_in));
            let how = InputGradient::Relu(&tape.inputs[i]);
            record_input_gradient(gpu, plan, conv(i), images, dz, &d, how);
            d
        };
        let mut images = b.images;
        weights(plan, OUT, images, &b.d_y);
        let mut d = through(plan, OUT, images, &b.d_y);
        // Decoder, last level first; each level's joined-input gradient holds its skip's.
        let mut d_joined = vec![None; LEVELS];
        for u in (0..LEVELS).rev() {
            let i = DECODER + u;
            weights(plan, i, images, &d);
            let joined = gpu.buffer(images.values(self.convs[i].c_in));
            record_input_gradient(
                gpu,
                plan,
                conv(i),
                images,
                &d,
                &joined,
                InputGradient::Write,
            );
            images = Images {
                views,
                h: images.h / 2,
                w: images.w / 2,
            };
            let c_x = self.convs[i - 1].c_out;
            d = gpu.buffer(images.values(c_x));
            let p = [
                c_x,
                self.convs[i].c_in - c_x,
                images.h,
                images.w,
                views,
                0,
                0,
                0,
            ];
            plan.push(gpu.prepare(
                &UPSAMPLE_BACKWARD,
                &p.map(|v| v as u32),
                &[&joined, &tape.outputs[i - 1], &d],
                groups_for(images.values(c_x)),
            ));
            d_joined[LEVELS - 1 - u] = Some(joined);
        }
        // Bottleneck: its second convolution, the offsets (and the ReLU before them), its
        // first.
        weights(plan, BOTTLENECK + 1, images, &d);
        let shifted = gpu.buffer(images.values(self.offset_width()));
        let how = InputGradient::Write;
        record_input_gradient(gpu, plan, conv(BOTTLENECK + 1), images, &d, &shifted, how);
        let planes = views * self.offset_width();
        plan.push(gpu.prepare(
            &OFFSET_BACKWARD,
            &[planes, images.h * images.w, 0, 0].map(|v| v as u32),
            &[&tape.outputs[BOTTLENECK], &shifted, &b.d_offsets],
            groups_for(planes),
        ));
        weights(plan, BOTTLENECK, images, &shifted);
        let mut d_pooled = gpu.buffer(images.values(self.convs[BOTTLENECK].c_in));
        let how = InputGradient::Write;
        record_input_gradient(
            gpu,
            plan,
            conv(BOTTLENECK),
            images,
            &shifted,
            &d_pooled,
            how,
        );
        // Encoder levels, deepest first: the pool's and the skip's gradients, then the
        // level's two convolutions.
        for l in (0..LEVELS).rev() {
            images = Images {
                views,
                h: images.h * 2,
                w: images.w * 2,
            };
            let c = self.convs[2 * l + 1].c_out;
            let c_up = self.convs[DECODER + LEVELS - 1 - l].c_in - c;
            let dz = gpu.buffer(images.values(c));
            let joined = d_joined[l].as_ref().expect("every level's joined gradient");
            plan.push(gpu.prepare(
                &POOL_BACKWARD,
                &[c, images.h, images.w, views, c_up, 0, 0, 0].map(|v| v as u32),
                &[
                    &tape.taken[l],
                    &d_pooled,
                    joined,
                    &tape.outputs[2 * l + 1],
                    &dz,
                ],
                groups_for(images.values(c)),
            ));
            weights(plan, 2 * l + 1, images, &dz);
            let d_a = through(plan, 2 * l + 1, images, &dz);
            weights(plan, 2 * l, images, &d_a);
            if l > 0 {
                d_pooled = gpu.buffer(images.values(self.convs[2 * l].c_in));
                let how = InputGradient::Write;
                record_input_gradient(gpu, plan, conv(2 * l), images, &d_a, &d_pooled, how);
            }
        }
        self.code_backward(gpu, plan, [params, grads], b);
        let buffers = [params, grads];
        self.encoder
            .record_backward(gpu, plan, buffers, views, &b.d_codes, &tape.encoder);
    }

    /// The code layer's gradients from the offsets', and the gradient at the codes.
    fn code_backward(
        &self,
        gpu: &GpuDevice,
        plan: &mut Vec<Dispatch>,
        [params, grads]: [&wgpu::Buffer; 2],
        b: &UnetBuffers,
    ) {
        let (views, width) = (b.images.views, self.code.d_out);
        plan.push(gpu.product(
            [CODE_SIZE, width, views],
            Operand::transposed(&b.codes, 0, CODE_SIZE),
            Operand::plain(&b.d_offsets, 0, width),
            Bias::None,
            0,
            Output::to(grads, self.code.weight.offset, width),
            None,
        ));
        let bias = Output::to(grads, self.code.bias.offset, width);
        gpu.column_sum(plan, &b.d_offsets, views, width, None, bias);
        plan.push(gpu.product(
            [views, CODE_SIZE, width],
            Operand::plain(&b.d_offsets, 0, width),
            Operand::transposed(params, self.code.weight.offset, width),
            Bias::None,
            0,
            Output::to(&b.d_codes, 0, CODE_SIZE),
            None,
        ));
    }
}

/// Appends to `plan` the 2 × 2 max-pool of `x` (`c` channels of `images`): returns the pooled
/// values, which of its window each took, and the pooled images.
fn record_pool(
    gpu: &GpuDevice,
    plan: &mut Vec<Dispatch>,
    x: &wgpu::Buffer,
    images: Images,
    c: usize,
) -> (wgpu::Buffer, wgpu::Buffer, Images) {
    let half = Images {
        views: images.views,
        h: images.h / 2,
        w: images.w / 2,
    };
    let (pooled, taken) = (gpu.buffer(half.values(c)), gpu.buffer(half.values(c)));
    plan.push(gpu.prepare(
        &MAX_POOL,
        &[images.views * c, images.h, images.w, 0].map(|v| v as u32),
        &[x, &pooled, &taken],
        groups_for(half.values(c)),
    ));
    (pooled, taken, half)
}

/// Appends to `plan` a decoder level's input: `x` (`c_x` channels of `images`) up-sampled and
/// joined with `skip`, `c_in` channels in all. Returns it and its images.
fn record_join(
    gpu: &GpuDevice,
    plan: &mut Vec<Dispatch>,
    [x, skip]: [&wgpu::Buffer; 2],
    images: Images,
    [c_x, c_in]: [usize; 2],
) -> (wgpu::Buffer, Images) {
    let full = Images {
        views: images.views,
        h: images.h * 2,
        w: images.w * 2,
    };
    let joined = gpu.buffer(full.values(c_in));
    let p = [c_x, c_in - c_x, images.h, images.w, images.views, 0, 0, 0];
    plan.push(gpu.prepare(
        &UPSAMPLE_CONCAT,
        &p.map(|v| v as u32),
        &[x, skip, &joined],
        groups_for(full.values(c_in)),
    ));
    (joined, full)
}

/// Appends to `plan` the masked `loss` of the output `y` (`images` of 3 channels) against
/// `b`'s radiance: the prediction into `b.prediction`, the gradient at `y` into `b.d_y`, the
/// sum into `b.loss`. Returns the index in `plan` of the loss's dispatch.
fn record_loss(
    gpu: &GpuDevice,
    plan: &mut Vec<Dispatch>,
    y: &wgpu::Buffer,
    b: &UnetBuffers,
    images: Images,
    loss: Loss,
) -> usize {
    let at = plan.len();
    plan.push(gpu.prepare(
        &UNET_LOSS,
        &loss_params(images, loss, 0.0),
        &[
            y,
            &b.radiance,
            &b.mask,
            &b.scale,
            &b.prediction,
            &b.d_y,
            &b.values,
        ],
        groups_for(images.values(3)),
    ));
    gpu.column_sum(
        plan,
        &b.values,
        images.values(3),
        1,
        None,
        Output::to(&b.loss, 0, 1),
    );
    at
}
