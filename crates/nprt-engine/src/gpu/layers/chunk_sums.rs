//! Gradients summed per chunk of rows into blocks laid out as a span of the parameters, then
//! added over the chunks in order by one column sum into that span: what several tensors'
//! sums (an MLP's weight gradients in a mixed-precision step, the light encoder's
//! convolutions') share, so that one dispatch adds them all. The gaps between the tensors, and
//! whatever no sums take, are added as zeros. A block may hold sums past the span's (a first
//! shading layer's per view), which the same column sum sends to a buffer of their own.

use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::operands::{Output, Tail};
use nprt_gpu::{Dispatch, GpuDevice, Span};

/// `chunks` blocks of sums, each laid out as the parameters' span `[base, base + len)`, then
/// `extra` sums more.
pub struct ChunkSums {
    pub sums: wgpu::Buffer,
    pub base: usize,
    /// The span's length.
    pub len: usize,
    /// A block's length, a chunk's stride in `sums`: the span's and the extra sums'.
    pub stride: usize,
    chunks: usize,
}

impl ChunkSums {
    /// Zero blocks for `chunks` chunks of the span `[base, base + len)` and `extra` sums more.
    pub fn new(gpu: &GpuDevice, [base, len, extra]: [usize; 3], chunks: usize) -> Self {
        ChunkSums {
            sums: gpu.buffer(chunks * (len + extra)),
            base,
            len,
            stride: len + extra,
            chunks,
        }
    }

    /// [`Self::new`] for the span from `first`'s start to `last`'s end.
    pub fn spanning(gpu: &GpuDevice, [first, last]: [Span; 2], chunks: usize) -> Self {
        let len = last.offset + last.len - first.offset;
        Self::new(gpu, [first.offset, len, 0], chunks)
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

    /// Appends to `plan` the sums over the chunks into the span of `grads`, and the extra
    /// sums into `extra` (from its start), which is given where there are any.
    pub fn record_total(
        &self,
        gpu: &GpuDevice,
        plan: &mut Vec<Dispatch>,
        grads: &wgpu::Buffer,
        extra: Option<&wgpu::Buffer>,
    ) {
        assert_eq!(
            extra.is_some(),
            self.stride > self.len,
            "a buffer for the extra sums, where a block has them"
        );
        let out = Output {
            tail: extra.map(|buffer| Tail {
                at: self.len,
                buffer,
                offset: 0,
            }),
            ..Output::to(grads, self.base, self.len)
        };
        gpu.column_sum(plan, &self.sums, self.chunks, self.stride, None, out);
    }
}
