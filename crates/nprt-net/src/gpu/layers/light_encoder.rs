//! The light encoder recorded on the device, once for both callers: a training step (over a
//! batch's maps, keeping each block's pooling tape for backward) and the frame path (over one
//! map, keeping nothing). Each convolution block halves the image; the code layer follows.

use crate::gpu::kernels::{ENCODER_BLOCK, ENCODER_BLOCK_THREADS};
use crate::gpu::layers::layer_at::{ConvAt, DenseAt};
use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::operands::{Bias, Operand, Output};
use crate::network::encoder::{LightEncoder, CHANNELS, CODE_SIZE};
use nprt_gpu::{groups_for, Bind, Dispatch, GpuDevice, Part, Span};

/// The light encoder's tensors in the flat buffers: its blocks' convolutions and the code
/// layer.
pub struct EncoderAt {
    pub convs: Vec<ConvAt>,
    pub to_code: DenseAt,
}

impl EncoderAt {
    /// `encoder`'s places, its tensors' spans taken in its visiting order from `spans`.
    pub fn new(encoder: &LightEncoder, spans: &mut impl Iterator<Item = Span>) -> Self {
        let convs = (encoder.convs.iter())
            .map(|c| ConvAt::new(c, spans))
            .collect();
        let to_code = DenseAt::new(&encoder.to_code, spans);
        EncoderAt { convs, to_code }
    }

    /// Appends to `plan` the light encoder over `views` maps `width` × `width / 2` in `input`
    /// (view-major, channel-major), its weights in `params`: the blocks (each with `keep` its
    /// pooling tape), then the code layer into `codes` (`views × CODE_SIZE`).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        gpu: &GpuDevice,
        plan: &mut Vec<Dispatch>,
        params: &wgpu::Buffer,
        input: &wgpu::Buffer,
        [views, width]: [usize; 2],
        codes: &wgpu::Buffer,
        keep: bool,
    ) -> BlockPass {
        let part = |span| Part {
            buffer: params,
            span,
        };
        // The parts are bound by reference: made first, then borrowed.
        let parts: Vec<_> = (self.convs.iter())
            .map(|conv| (part(conv.weight), part(conv.bias), conv.c_in))
            .collect();
        let blocks: Vec<BlockWeights> = (parts.iter())
            .map(|(weight, bias, c_in)| BlockWeights {
                weight,
                bias,
                c_in: *c_in,
            })
            .collect();
        let pass = record_blocks(gpu, plan, input, [views, width], &blocks, keep);
        let (to_code, flat) = (&self.to_code, self.to_code.d_in);
        plan.push(gpu.product(
            [views, CODE_SIZE, flat],
            Operand::plain(&pass.last, 0, flat),
            Operand::plain(params, to_code.weight.offset, CODE_SIZE),
            Bias::Column(params, to_code.bias.offset),
            0,
            Output::to(codes, 0, CODE_SIZE),
            None,
        ));
        pass
    }
}

/// One block's weights as its caller binds them, and its input channels.
struct BlockWeights<'a> {
    pub weight: &'a dyn Bind,
    pub bias: &'a dyn Bind,
    pub c_in: usize,
}

/// What recording the blocks leaves: each block's input and its (h, w), each block's pooling
/// tape when kept, and the last block's output (the code layer's flattened input).
pub struct BlockPass {
    pub inputs: Vec<wgpu::Buffer>,
    pub sizes: Vec<(usize, usize)>,
    pub tapes: Vec<wgpu::Buffer>,
    pub last: wgpu::Buffer,
}

/// Appends to `plan` the blocks over `views` maps `width` × `width / 2` in `input`
/// (view-major, channel-major), each with `keep` its pooling tape.
fn record_blocks(
    gpu: &GpuDevice,
    plan: &mut Vec<Dispatch>,
    input: &wgpu::Buffer,
    [views, width]: [usize; 2],
    blocks: &[BlockWeights],
    keep: bool,
) -> BlockPass {
    let (mut h, mut w) = (width / 2, width);
    let mut pass = BlockPass {
        inputs: Vec::with_capacity(blocks.len()),
        sizes: Vec::with_capacity(blocks.len()),
        tapes: Vec::new(),
        last: input.clone(),
    };
    for b in blocks {
        let count = views * CHANNELS * (h / 2) * (w / 2);
        let out = gpu.buffer(count);
        let tape = if keep {
            gpu.buffer(count)
        } else {
            gpu.empty.clone()
        };
        let params = [b.c_in, h, w, views, usize::from(keep), 0, 0, 0].map(|v| v as u32);
        plan.push(gpu.prepare(
            &ENCODER_BLOCK,
            &params,
            &[&pass.last, b.weight, b.bias, &out, &tape],
            groups_for(ENCODER_BLOCK_THREADS * count),
        ));
        pass.inputs.push(std::mem::replace(&mut pass.last, out));
        pass.sizes.push((h, w));
        if keep {
            pass.tapes.push(tape);
        }
        (h, w) = (h / 2, w / 2);
    }
    pass
}
