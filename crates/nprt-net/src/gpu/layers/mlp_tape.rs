//! What an MLP's forward pass in a training step keeps for its backward pass (`MlpTape`), and
//! how rows a fused pass writes in one dispatch lie in one buffer. Written by
//! `network_forward`, read by `passes`' backward.

use crate::gpu::layers::network_layout::MlpAt;
use crate::gpu::products::half_layers::held_halves;
use nprt_gpu::{GpuDevice, Part, Span};

/// What an MLP's forward pass keeps for backward: each hidden layer's output and
/// pre-activation, the last layer's output, and in a mixed-precision step the input as f16 rows
/// too (the hidden outputs are f16 rows there, `half_products`). The pre-activations share a
/// buffer, each from an offset a kernel can bind alone. So do the input and hidden outputs
/// where a fused pass writes them all in one dispatch (`half_mlp`); elsewhere each has a buffer
/// of its own, since a layer a dispatch reads the layer before's output while it writes its
/// own, and a dispatch cannot bind one buffer both ways.
pub struct MlpTape {
    pub rows: usize,
    pub output: wgpu::Buffer,
    /// The input's f16 rows first in a mixed-precision step, then the hidden outputs.
    held: HeldRows,
    pre: wgpu::Buffer,
    pre_at: Vec<Span>,
    half: bool,
    /// Whether a fused pass writes it (its held rows in one buffer).
    fused: bool,
}

/// Where a fused forward pass writes a tape (`half_mlp`): the buffer of f16 rows, the input's
/// place there, and each hidden layer's places (`[its f16 output in held, its pre-activation
/// in pre]`), counted in values.
pub struct Kept<'a> {
    pub held: &'a wgpu::Buffer,
    pub pre: &'a wgpu::Buffer,
    pub input_at: usize,
    pub layers: Vec<[usize; 2]>,
}

impl MlpTape {
    /// Buffers for `m`'s forward pass over `rows` rows; in a mixed-precision step its input
    /// and hidden layers' outputs as f16 rows (`half_products`), in one buffer where a fused
    /// pass runs the MLP.
    pub fn new(gpu: &GpuDevice, m: &MlpAt, rows: usize) -> MlpTape {
        let half = !m.half.is_empty();
        let last = m.layers.len() - 1;
        // f16 rows take half a word a value (a held row block is a whole number of words).
        let words = |width: usize| match half {
            true => held_halves(rows, width) / 2,
            false => rows * width,
        };
        let input = half.then(|| words(m.half[0].count));
        let widths = m.layers[..last].iter().map(|l| l.d_out);
        let held_words = input.into_iter().chain(widths.clone().map(words));
        let fused = half && m.fuses(gpu);
        let held = held_rows(gpu, held_words, fused);
        let (pre_at, pre_end) = spans(gpu, widths.map(|d| rows * d));
        MlpTape {
            rows,
            output: gpu.buffer(rows * m.layers[last].d_out),
            held,
            pre: gpu.buffer(pre_end),
            pre_at,
            half,
            fused,
        }
    }

    /// Hidden layer `i`'s output: f32 rows, or f16 rows as `Held::F16` holds them.
    pub fn hidden(&self, i: usize) -> Part<'_> {
        self.held.part(i + usize::from(self.half))
    }

    /// Hidden layer `i`'s pre-activation, f32 rows.
    pub fn pre(&self, i: usize) -> Part<'_> {
        Part {
            buffer: &self.pre,
            span: self.pre_at[i],
        }
    }

    /// The input as f16 rows, in a mixed-precision step.
    pub fn input16(&self) -> Option<Part<'_>> {
        self.half.then(|| self.held.part(0))
    }

    /// Where a fused forward pass writes this tape (`half_mlp`), its f16 rows' places counted
    /// in halves; `None` for a tape a layer a dispatch writes.
    pub fn kept(&self) -> Option<Kept<'_>> {
        self.fused.then(|| {
            let input = self.held.part(0);
            Kept {
                held: input.buffer,
                pre: &self.pre,
                input_at: 2 * input.span.offset,
                layers: (self.held.0[1..].iter().zip(&self.pre_at))
                    .map(|((_, h), z)| [2 * h.offset, z.offset])
                    .collect(),
            }
        })
    }
}

/// Spans of `lens` words one after another, each from a multiple of `gpu`'s storage-binding
/// alignment, and the words they take (at least one).
fn spans(gpu: &GpuDevice, lens: impl Iterator<Item = usize>) -> (Vec<Span>, usize) {
    let align = gpu.binding_alignment();
    let mut end = 0;
    let spans = lens
        .map(|len| {
            let offset = end;
            end = (offset + len).next_multiple_of(align);
            Span { offset, len }
        })
        .collect();
    (spans, end.max(1))
}

/// Rows a layer at a time, each bound alone (`held_rows`): a buffer each, or one buffer's
/// parts.
pub(crate) struct HeldRows(Vec<(wgpu::Buffer, Span)>);

impl HeldRows {
    /// Layer `i`'s rows.
    pub fn part(&self, i: usize) -> Part<'_> {
        let (buffer, span) = &self.0[i];
        Part {
            buffer,
            span: *span,
        }
    }
}

/// Rows of `lens` words each: in one buffer at offsets a kernel can bind alone where `shared`
/// (what a fused pass writes in one dispatch), else a buffer each (a layer a dispatch reads
/// one while it writes the next, which one buffer cannot serve).
pub(crate) fn held_rows(
    gpu: &GpuDevice,
    lens: impl Iterator<Item = usize>,
    shared: bool,
) -> HeldRows {
    if !shared {
        let own = |len: usize| (gpu.buffer(len.max(1)), Span { offset: 0, len });
        return HeldRows(lens.map(own).collect());
    }
    let (spans, end) = spans(gpu, lens);
    let buffer = gpu.buffer(end);
    HeldRows(spans.into_iter().map(|s| (buffer.clone(), s)).collect())
}
