//! Gradients summed per chunk of rows into blocks laid out as a span of the parameters, then
//! added over the chunks in order by one column sum into that span: what several tensors'
//! sums (an MLP's weight gradients in a mixed-precision step, the light encoder's
//! convolutions') share, so that one dispatch adds them all. The gaps between the tensors, and
//! whatever no sums take, are added as zeros.

use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::operands::Output;
use nprt_gpu::{Dispatch, GpuDevice, Span};

/// `chunks` blocks of sums, each laid out as the parameters' span `[base, base + len)`.
pub struct ChunkSums {
    pub sums: wgpu::Buffer,
    pub base: usize,
    /// The span's length: a block's, and a chunk's stride in `sums`.
    pub len: usize,
    chunks: usize,
}

impl ChunkSums {
    /// Zero blocks for `chunks` chunks of the span `[base, base + len)`.
    pub fn new(gpu: &GpuDevice, [base, len]: [usize; 2], chunks: usize) -> Self {
        ChunkSums {
            sums: gpu.buffer(chunks * len),
            base,
            len,
            chunks,
        }
    }

    /// [`Self::new`] for the span from `first`'s start to `last`'s end.
    pub fn spanning(gpu: &GpuDevice, [first, last]: [Span; 2], chunks: usize) -> Self {
        let len = last.offset + last.len - first.offset;
        Self::new(gpu, [first.offset, len], chunks)
    }

    /// Where `span` of the parameters starts in a block; it must lie inside.
    pub fn at(&self, span: Span) -> usize {
        let at = span.offset - self.base;
        assert!(
            at + span.len <= self.len,
            "a tensor outside the summed span"
        );
        at
    }

    /// Appends to `plan` the sums over the chunks into the span of `grads`.
    pub fn record_total(&self, gpu: &GpuDevice, plan: &mut Vec<Dispatch>, grads: &wgpu::Buffer) {
        let out = Output::to(grads, self.base, self.len);
        gpu.column_sum(plan, &self.sums, self.chunks, self.len, None, out);
    }
}
