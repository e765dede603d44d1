//! The light encoder's convolution blocks recorded on the device, once for both callers: a
//! training step (over a batch's maps, keeping each block's pooling tape for backward) and the
//! frame path (over one map, keeping nothing). Each block halves the image; the code layer
//! after them is each caller's, as their weights are held differently.

use super::kernels::{ENCODER_BLOCK, ENCODER_BLOCK_THREADS};
use super::{groups_for, Bind, Dispatch, GpuDevice};
use crate::network::encoder::CHANNELS;

/// One block's weights as its caller binds them, and its input channels.
pub struct BlockWeights<'a> {
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
pub fn record_blocks(
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
