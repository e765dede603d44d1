//! Convolutions on the device, as the light encoder's backward pass and the Deep Shading
//! U-Net record them: its forward pass (the U-Net's; the
//! encoder fuses its own into `encoder_block`), the gradient at its input and its weights'
//! gradients.

use crate::gpu::kernels::{
    CONV_FORWARD, CONV_INPUT_BACKWARD, CONV_INPUT_BACKWARD_THREADS, CONV_WEIGHT_BACKWARD,
};
use crate::gpu::layers::chunk_sums::ChunkSums;
use crate::gpu::layers::layer_at::ConvAt;
use nprt_gpu::{groups_for, Dispatch, GpuDevice, Part};

/// Chunks of image rows a convolution's weight gradients are summed over, at most: enough
/// threads for a GPU (a 128 × 64 map's first encoder block at 8 maps: 256 chunks × 896
/// values), and few enough partial sums to add.
const CONV_CHUNKS: usize = 256;

/// A convolution's images: `views` of h × w.
#[derive(Clone, Copy)]
pub struct Images {
    pub views: usize,
    pub h: usize,
    pub w: usize,
}

impl Images {
    pub fn values(self, channels: usize) -> usize {
        self.views * channels * self.h * self.w
    }
}

/// Appends to `plan` the convolution of `input` into `out` (with ReLU after when `relu`), its
/// weights in `params`.
pub fn record_conv(
    gpu: &GpuDevice,
    plan: &mut Vec<Dispatch>,
    (conv, params): (&ConvAt, &wgpu::Buffer),
    images: Images,
    input: &wgpu::Buffer,
    out: &wgpu::Buffer,
    relu: bool,
) {
    let part = |span| Part {
        buffer: params,
        span,
    };
    let Images { views, h, w } = images;
    let p = [
        conv.c_in,
        conv.c_out,
        h,
        w,
        views,
        conv.k,
        usize::from(relu),
        0,
    ];
    plan.push(gpu.prepare(
        &CONV_FORWARD,
        &p.map(|v| v as u32),
        &[input, &part(conv.weight), &part(conv.bias), out],
        groups_for(images.values(conv.c_out)),
    ));
}

/// How [`record_input_gradient`] leaves the gradient at a convolution's input.
pub enum InputGradient<'a> {
    /// Written, or added to what the buffer holds.
    Write,
    Add,
    /// Written where the input (a ReLU's output, this buffer) is positive, zero elsewhere:
    /// the gradient at that ReLU's input.
    Relu(&'a wgpu::Buffer),
}

/// Appends to `plan` the gradient at a convolution's input from the gradient `dz` at its
/// pre-activation, into `d_input`.
pub fn record_input_gradient(
    gpu: &GpuDevice,
    plan: &mut Vec<Dispatch>,
    (conv, params): (&ConvAt, &wgpu::Buffer),
    images: Images,
    dz: &wgpu::Buffer,
    d_input: &wgpu::Buffer,
    how: InputGradient,
) {
    let Images { views, h, w } = images;
    let (add, act) = match how {
        InputGradient::Write => (false, None),
        InputGradient::Add => (true, None),
        InputGradient::Relu(act) => (false, Some(act)),
    };
    let p = [
        conv.c_in,
        conv.c_out,
        h,
        w,
        views,
        conv.k,
        usize::from(add),
        usize::from(act.is_some()),
    ];
    let weight = Part {
        buffer: params,
        span: conv.weight,
    };
    plan.push(gpu.prepare(
        &CONV_INPUT_BACKWARD,
        &p.map(|v| v as u32),
        &[&weight, dz, act.unwrap_or(&gpu.empty), d_input],
        groups_for(CONV_INPUT_BACKWARD_THREADS * images.values(conv.c_in)),
    ));
}

/// Chunks of image rows a convolution over `images` sums its weight gradients over, and the
/// rows a chunk.
fn row_chunks(images: Images) -> [usize; 2] {
    let rows = images.views * images.h;
    let chunk_rows = rows.div_ceil(CONV_CHUNKS);
    [chunk_rows, rows.div_ceil(chunk_rows)]
}

/// Where `convs`' weight and bias gradients are summed per chunk of image rows, each with the
/// images it runs over (they lie in the parameters one after another): blocks laid out as the
/// parameters from the first's weight to the last's bias, as many as the convolution with the
/// most chunks needs (one with fewer leaves the rest of its blocks zero).
pub fn conv_sums(gpu: &GpuDevice, convs: &[(&ConvAt, Images)]) -> ChunkSums {
    let chunks = (convs.iter())
        .map(|&(_, images)| row_chunks(images)[1])
        .max()
        .unwrap_or(1);
    let last = convs[convs.len() - 1].0.bias;
    ChunkSums::spanning(gpu, [convs[0].0.weight, last], chunks)
}

/// Appends to `plan` the sums per chunk of image rows of a convolution's weight and bias
/// gradients into `to`'s blocks, from its `input` and the gradient `dz` at its pre-activation
/// ([`ChunkSums::record_total`] then adds the chunks).
pub fn record_weight_sums(
    gpu: &GpuDevice,
    plan: &mut Vec<Dispatch>,
    (conv, to): (&ConvAt, &ChunkSums),
    images: Images,
    input: &wgpu::Buffer,
    dz: &wgpu::Buffer,
) {
    let Images { views, h, w } = images;
    let [chunk_rows, chunks] = row_chunks(images);
    let taps = conv.c_in * conv.k * conv.k;
    let [w_at, b_at] = [conv.weight, conv.bias].map(|s| to.at(s));
    let p = [
        conv.c_in, conv.c_out, h, w, views, conv.k, chunk_rows, chunks, to.stride, w_at, b_at, 0,
    ];
    plan.push(gpu.prepare(
        &CONV_WEIGHT_BACKWARD,
        &p.map(|v| v as u32),
        &[input, dz, &to.sums],
        groups_for(chunks * conv.c_out * (taps + 1)),
    ));
}

/// Appends to `plan` the gradients of one convolution's weights and biases, into their spans
/// of `grads`: [`record_weight_sums`] and their total.
pub fn record_weight_gradients(
    gpu: &GpuDevice,
    plan: &mut Vec<Dispatch>,
    (conv, grads): (&ConvAt, &wgpu::Buffer),
    images: Images,
    input: &wgpu::Buffer,
    dz: &wgpu::Buffer,
) {
    let sums = conv_sums(gpu, &[(conv, images)]);
    record_weight_sums(gpu, plan, (conv, &sums), images, input, dz);
    sums.record_total(gpu, plan, grads, None);
}
