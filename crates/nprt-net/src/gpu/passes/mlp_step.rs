//! An MLP's share of a training step: the buffers its forward pass keeps for backward, and its
//! backward pass into every layer's gradients (the weights' summed over chunks of rows).

use crate::gpu::kernels::GEMM_TILE;
use crate::gpu::layers::network_forward::ForwardTargets;
use crate::gpu::layers::network_layout::MlpAt;
use crate::gpu::products::codes::{activation_code, BACKWARD};
use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::half_layers::held_halves;
use crate::gpu::products::half_layers::Held;
use crate::gpu::products::operands::{Bias, Operand, Output};
use nprt_gpu::{Dispatch, GpuDevice};

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

/// What an MLP's forward pass keeps: each layer's output and each hidden layer's
/// pre-activation; in a mixed-precision step also its input as f16 rows, and the hidden
/// layers' outputs are f16 rows (`half_products`).
pub struct MlpTape {
    pub rows: usize,
    pub input16: Option<wgpu::Buffer>,
    pub outputs: Vec<wgpu::Buffer>,
    pub pre: Vec<wgpu::Buffer>,
}

/// What `m`'s forward pass writes into `tape`: each layer's output (the hidden ones f16 in
/// a mixed-precision step) and pre-activation.
pub fn forward_targets<'a>(m: &MlpAt, tape: &'a MlpTape) -> ForwardTargets<'a> {
    let half = !m.half.is_empty();
    let last = tape.outputs.len() - 1;
    ForwardTargets {
        outputs: (tape.outputs.iter().enumerate())
            .map(|(i, b)| match half && i < last {
                true => Held::F16(b),
                false => Held::F32(b),
            })
            .collect(),
        pre: Some(&tape.pre),
        input16: tape.input16.as_ref(),
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
    /// and hidden layers' outputs as f16 rows (`half_products`).
    pub fn tape(&self, m: &MlpAt, rows: usize) -> MlpTape {
        let half = !m.half.is_empty();
        let last = m.layers.len() - 1;
        MlpTape {
            rows,
            input16: half.then(|| self.gpu.half_buffer(held_halves(rows, m.half[0].count))),
            outputs: m
                .layers
                .iter()
                .enumerate()
                .map(|(i, l)| match half && i < last {
                    true => self.gpu.half_buffer(held_halves(rows, l.d_out)),
                    false => self.gpu.buffer(rows * l.d_out),
                })
                .collect(),
            pre: m.layers[..last]
                .iter()
                .map(|l| self.gpu.buffer(rows * l.d_out))
                .collect(),
        }
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
            let (x, own_row, count) = match i {
                0 => input,
                _ => (&tape.outputs[i - 1], 0, layer.d_in),
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
                Operand::transposed(x, 0, count),
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
            let (dx, derivative, pre) = match i {
                0 => match d_input {
                    Some(d) => (d, 0, None),
                    None => continue,
                },
                _ => (
                    &scratch[(i - 1) % 2],
                    activation_code(m.activation) + BACKWARD,
                    Some(&tape.pre[i - 1]),
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
