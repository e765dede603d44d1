//! An MLP's share of a training step: its backward pass into every layer's gradients (the
//! weights' summed over chunks of rows) from what its forward pass kept (`MlpTape`).

use crate::gpu::kernels::GEMM_TILE;
use crate::gpu::layers::layer_at::DenseAt;
use crate::gpu::layers::mlp_tape::MlpTape;
use crate::gpu::layers::network_layout::MlpAt;
use crate::gpu::products::codes::{activation_code, BACKWARD};
use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::operands::{Bias, Operand, Output, Tail};
use nprt_gpu::{Bind, Dispatch, GpuDevice};

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

/// A first layer whose bias is a row per view (the light code's share, `Bias::Group`): the
/// sums of the gradient at its pre-activation over each view's rows (`views` × its width, into
/// `d_views`) make its bias's gradient, and `then` records what else follows from them (the
/// code's rows of the weight, the code's gradient).
pub struct ViewSums<'a> {
    /// Each batch row's view.
    pub view: &'a wgpu::Buffer,
    pub views: usize,
    pub d_views: &'a wgpu::Buffer,
    pub then: &'a dyn Fn(&mut Vec<Dispatch>),
}

/// What an MLP's training records against: the device, the flat parameters it reads and the
/// gradients it writes (a design's trainer's, or the radiance cache's).
pub struct Trainable<'a> {
    pub gpu: &'a GpuDevice,
    pub params: &'a wgpu::Buffer,
    pub grads: &'a wgpu::Buffer,
}

impl Trainable<'_> {
    /// Records the backward pass of `m` from the gradient `d_last` at its output: every
    /// layer's weight and bias gradient into `grads`, and the gradient at its input into
    /// `d_input` where given. `input` is what the first layer read: the buffer, its first
    /// weight row and its values per row. With `view_sums` the first layer's bias is a row per
    /// view, whose gradient comes from the sums per view.
    #[allow(clippy::too_many_arguments)]
    pub fn mlp_backward(
        &self,
        plan: &mut Vec<Dispatch>,
        m: &MlpAt,
        tape: &MlpTape,
        input: (&wgpu::Buffer, usize, usize),
        d_last: &wgpu::Buffer,
        d_input: Option<&wgpu::Buffer>,
        view_sums: Option<&ViewSums>,
    ) {
        if !m.half.is_empty() {
            return self.half_mlp_backward(plan, m, tape, d_last, d_input, view_sums);
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
            // The bias's gradient (unless it comes from the sums per view) rides on the
            // weight's product as a row of ones in A where that product's last tile has a row
            // to spare; otherwise the extra row would cost a row of tiles, and a column sum is
            // cheaper.
            let per_view = view_sums.filter(|_| i == 0);
            let spare_row = !count.is_multiple_of(GEMM_TILE as usize);
            let folded = per_view.is_none() && spare_row;
            self.sum_over_rows(
                plan,
                [count, layer.d_out, rows],
                Operand::transposed(x, x_at, count),
                Operand::plain(dz, 0, layer.d_out),
                weights,
                folded.then_some(layer.bias.offset),
            );
            if !folded {
                self.bias_gradient(plan, layer, (dz, rows), per_view);
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

    /// Records the gradient of `layer`'s bias from the gradient `dz` at its `rows` outputs:
    /// their sum, or with `per_view` their sums per view, then those summed.
    fn bias_gradient(
        &self,
        plan: &mut Vec<Dispatch>,
        layer: &DenseAt,
        (dz, rows): (&wgpu::Buffer, usize),
        per_view: Option<&ViewSums>,
    ) {
        let bias = Output::to(self.grads, layer.bias.offset, layer.d_out);
        match per_view {
            Some(v) => {
                let to = Output::to(v.d_views, 0, layer.d_out);
                let views = Some((v.view, v.views));
                (self.gpu).column_sum(plan, dz, rows, layer.d_out, views, to);
                (self.gpu).column_sum(plan, v.d_views, v.views, layer.d_out, None, bias);
                (v.then)(plan);
            }
            None => self.gpu.column_sum(plan, dz, rows, layer.d_out, None, bias),
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
            out.tail = Some(Tail {
                at: m * n,
                buffer: self.grads,
                offset: at,
            });
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
