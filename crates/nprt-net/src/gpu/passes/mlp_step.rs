//! An MLP's share of a training step: the buffers its forward pass keeps for backward, and its
//! backward pass into every layer's gradients (the weights' summed over chunks of rows).

use crate::gpu::kernels::GEMM_TILE;
use crate::gpu::layers::network_layout::MlpAt;
use crate::gpu::products::codes::{activation_code, BACKWARD};
use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::half_layers::held_halves;
use crate::gpu::products::half_mlp::Kept;
use crate::gpu::products::operands::{Bias, Operand, Output};
use nprt_gpu::{Bind, Dispatch, GpuDevice, Part, Span};

/// A weight gradient's product is split into chunks of at least ROW_CHUNK rows, at most
/// ROW_CHUNKS of them (a 256 × 256 layer at batch 16,384: 32 chunks of 512 rows, 512
/// workgroups instead of 16).
const ROW_CHUNK: usize = 256;
const ROW_CHUNKS: usize = 32;

/// How a weight gradient's sum over `rows` rows is split: `[rows a chunk, chunks]`, each chunk
/// a multiple of `align` rows (a tensor-core product's tile side; 1 for `gemm`).
pub(crate) fn row_chunks(rows: usize, align: usize) -> [usize; 2] {
    let chunk = rows
        .div_ceil(ROW_CHUNKS)
        .next_multiple_of(align)
        .max(ROW_CHUNK);
    [chunk, rows.div_ceil(chunk)]
}

/// What takes a first layer's bias gradient, given the gradient at its pre-activation.
pub type FirstLayerBias<'a> = &'a dyn Fn(&mut Vec<Dispatch>, &wgpu::Buffer);

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
    held: Vec<(wgpu::Buffer, Span)>,
    pre: wgpu::Buffer,
    pre_at: Vec<Span>,
    half: bool,
}

impl MlpTape {
    /// Hidden layer `i`'s output: f32 rows, or f16 rows as `Held::F16` holds them.
    pub fn hidden(&self, i: usize) -> Part<'_> {
        self.held(i + usize::from(self.half))
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
        self.half.then(|| self.held(0))
    }

    /// Where a fused forward pass writes this tape (`half_mlp`), its f16 rows' places counted
    /// in halves; `None` for a tape a layer a dispatch writes.
    pub fn kept(&self) -> Option<Kept<'_>> {
        let (buffer, input) = self.held.first().filter(|_| self.half)?;
        let shared = self.held.iter().all(|(b, _)| b == buffer);
        shared.then(|| Kept {
            held: buffer,
            pre: &self.pre,
            input_at: 2 * input.offset,
            layers: (self.held[1..].iter().zip(&self.pre_at))
                .map(|((_, h), z)| [2 * h.offset, z.offset])
                .collect(),
        })
    }

    fn held(&self, i: usize) -> Part<'_> {
        let (buffer, span) = &self.held[i];
        Part {
            buffer,
            span: *span,
        }
    }
}

/// What an MLP's training records against: the device, the flat parameters it reads and the
/// gradients it writes (a design's trainer's, or the radiance cache's).
pub struct Trainable<'a> {
    pub gpu: &'a GpuDevice,
    pub params: &'a wgpu::Buffer,
    pub grads: &'a wgpu::Buffer,
}

impl Trainable<'_> {
    /// Buffers for an MLP's forward pass over `rows` rows; in a mixed-precision step its input
    /// and hidden layers' outputs as f16 rows (`half_products`), in one buffer where a fused
    /// pass runs the MLP.
    pub fn tape(&self, m: &MlpAt, rows: usize) -> MlpTape {
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
        let held = match half && m.fuses(self.gpu) {
            true => {
                let (spans, end) = self.spans(held_words);
                let buffer = self.gpu.buffer(end);
                let shared = spans.into_iter().map(|s| (buffer.clone(), s));
                shared.collect()
            }
            false => held_words
                .map(|len| (self.gpu.buffer(len.max(1)), Span { offset: 0, len }))
                .collect(),
        };
        let (pre_at, pre_end) = self.spans(widths.map(|d| rows * d));
        MlpTape {
            rows,
            output: self.gpu.buffer(rows * m.layers[last].d_out),
            held,
            pre: self.gpu.buffer(pre_end),
            pre_at,
            half,
        }
    }

    /// Spans of `lens` words one after another, each from a multiple of the device's
    /// storage-binding alignment, and the words they take (at least one).
    fn spans(&self, lens: impl Iterator<Item = usize>) -> (Vec<Span>, usize) {
        let align = self.gpu.device.limits().min_storage_buffer_offset_alignment as usize / 4;
        let mut end = 0;
        let spans = lens
            .map(|len| {
                let offset = end;
                end = (offset + len).next_multiple_of(align.max(1));
                Span { offset, len }
            })
            .collect();
        (spans, end.max(1))
    }

    /// Records the backward pass of `m` from the gradient `d_last` at its output: every
    /// layer's weight and bias gradient into `grads`, and the gradient at its input into
    /// `d_input` where given. `input` is what the first layer read: the buffer, its first
    /// weight row and its values per row. `on_first`, where given, takes the first layer's
    /// bias gradient (it also receives the light code's share), given the gradient at that
    /// layer's pre-activation.
    #[allow(clippy::too_many_arguments)]
    pub fn mlp_backward(
        &self,
        plan: &mut Vec<Dispatch>,
        m: &MlpAt,
        tape: &MlpTape,
        input: (&wgpu::Buffer, usize, usize),
        d_last: &wgpu::Buffer,
        d_input: Option<&wgpu::Buffer>,
        on_first: Option<FirstLayerBias>,
    ) {
        if !m.half.is_empty() {
            return self.half_mlp_backward(plan, m, tape, d_last, d_input, on_first);
        }
        let rows = tape.rows;
        let scratch = [0, 1].map(|_| self.gpu.buffer(rows * m.widest()));
        let last = m.layers.len() - 1;
        for (i, layer) in m.layers.iter().enumerate().rev() {
            // A hidden layer's dz is already the gradient at its pre-activation: the product
            // that made it applied the activation's derivative.
            let dz = if i == last { d_last } else { &scratch[i % 2] };
            let hidden;
            let (x, x_at, own_row, count) = match i {
                0 => (input.0, 0, input.1, input.2),
                _ => {
                    hidden = tape.hidden(i - 1);
                    (hidden.buffer, hidden.span.offset, 0, layer.d_in)
                }
            };
            let weights = layer.weight.offset + own_row * layer.d_out;
            // The bias's gradient (unless `on_first` takes it) rides on the weight's product as
            // a row of ones in A where that product's last tile has a row to spare; otherwise
            // the extra row would cost a row of tiles, and a column sum is cheaper.
            let first_bias = on_first.filter(|_| i == 0);
            let spare_row = !count.is_multiple_of(GEMM_TILE as usize);
            let folded = first_bias.is_none() && spare_row;
            self.sum_over_rows(
                plan,
                [count, layer.d_out, rows],
                Operand::transposed(x, x_at, count),
                Operand::plain(dz, 0, layer.d_out),
                weights,
                folded.then_some(layer.bias.offset),
            );
            match first_bias {
                Some(f) => f(plan, dz),
                None if !folded => self.gpu.column_sum(
                    plan,
                    dz,
                    rows,
                    layer.d_out,
                    None,
                    Output::to(self.grads, layer.bias.offset, layer.d_out),
                ),
                None => {}
            }
            // The gradient at the layer's input; below a hidden layer, times its activation's
            // derivative at the pre-activation there (`gemm`'s backward epilogue).
            let pre_part;
            let (dx, derivative, pre) = match i {
                0 => match d_input {
                    Some(d) => (d, 0, None),
                    None => continue,
                },
                _ => (
                    &scratch[(i - 1) % 2],
                    activation_code(m.activation) + BACKWARD,
                    {
                        pre_part = tape.pre(i - 1);
                        Some(&pre_part as &dyn Bind)
                    },
                ),
            };
            plan.push(self.gpu.product(
                [rows, count, layer.d_out],
                Operand::plain(dz, 0, layer.d_out),
                Operand::transposed(self.params, weights, layer.d_out),
                Bias::None,
                derivative,
                Output::to(dx, 0, count),
                pre,
            ));
        }
    }

    /// Records the gradients of a weight, `[m, n, rows]`: Aᵀ·B summed over the batch's rows,
    /// into `grads` from `offset` (row stride n), and with `bias` (its offset in `grads`) the
    /// bias's, B's column sums, from an extra row of A that reads as ones. Past [`ROW_CHUNK`]
    /// rows (or with a bias) the product is split over chunks of rows (at most
    /// [`ROW_CHUNKS`]) and the chunks' products added in order.
    fn sum_over_rows(
        &self,
        plan: &mut Vec<Dispatch>,
        [m, n, rows]: [usize; 3],
        mut a: Operand,
        b: Operand,
        offset: usize,
        bias: Option<usize>,
    ) {
        let [chunk, chunks] = row_chunks(rows, 1);
        let mut out = Output::to(self.grads, offset, n);
        if chunks <= 1 && bias.is_none() {
            plan.push(
                self.gpu
                    .product([m, n, rows], a, b, Bias::None, 0, out, None),
            );
            return;
        }
        let mut rows_of_c = m;
        if let Some(at) = bias {
            a.ones_row = Some(m);
            rows_of_c = m + 1;
            out.tail = Some([m * n, at]);
        }
        let partial = self.gpu.buffer(chunks * rows_of_c * n);
        plan.push(
            self.gpu
                .split_product([rows_of_c, n, rows], a, b, [chunk, chunks], &partial),
        );
        self.gpu
            .column_sum(plan, &partial, chunks, rows_of_c * n, None, out);
    }
}
