//! Recording primitives on the device: a strided matrix product with its epilogue (every
//! dense layer's, in training and in frames, and the products of their backward passes) and
//! sums of columns, each a dispatch or a few appended to a plan.

use crate::gpu::kernels::{COLUMN_SUM, GEMM, GEMM_TILE};
use crate::gpu::products::codes::BACKWARD;
use crate::gpu::products::operands::{Bias, Operand, Output};
use nprt_gpu::{groups_for, Bind, Dispatch, GpuDevice};

/// Rows a `column_sum` thread adds before the chunks' sums are added in a further pass (and
/// theirs in another, as a tree). Short: a thread's adds are a chain of dependent loads, and on
/// an H100 256 of them made each sum over a 16,384-row batch about 35 µs where the data takes a
/// few (`nprt bench train --profile`, 2026-11-27).
const COLUMN_CHUNK: usize = 64;
/// The matrix products of dense layers on the device (training's and the frame path's).
pub trait DenseProducts {
    /// The dispatch of C = A·B for `[m, n, k]` (C m × n), with `bias` and `activation` (0
    /// linear, 1 ReLU, 2 SIREN) after, the pre-activation kept in `z` where given: a dense
    /// layer's forward pass, and every product of its backward pass; `activation` 3 or 4
    /// multiplies by ReLU's or SIREN's derivative at the values `z` holds instead (the
    /// gradient at a hidden layer's pre-activation).
    #[allow(clippy::too_many_arguments)]
    fn product(
        &self,
        shape: [usize; 3],
        a: Operand,
        b: Operand,
        bias: Bias,
        activation: u32,
        c: Output,
        z: Option<&dyn Bind>,
    ) -> Dispatch;

    /// The dispatch of `chunks` products, each over `k_chunk` consecutive values of k (the last
    /// over what is left), into consecutive m × n blocks of `c` (row stride n), which
    /// [`DenseProducts::column_sum`] then adds: a product over many k (a weight's gradient over a
    /// batch) on chunks × tiles workgroups instead of tiles alone.
    fn split_product(
        &self,
        shape: [usize; 3],
        a: Operand,
        b: Operand,
        split: [usize; 2],
        c: &wgpu::Buffer,
    ) -> Dispatch;
    /// Records the sums over `rows` rows of the `n` columns of `x`, per group where `groups`
    /// gives each row's group and their number, into `out`. Past [`COLUMN_CHUNK`] rows the sums
    /// are made per chunk of rows, then over the chunks, in a fixed order either way.
    fn column_sum(
        &self,
        plan: &mut Vec<Dispatch>,
        x: &wgpu::Buffer,
        rows: usize,
        n: usize,
        groups: Option<(&wgpu::Buffer, usize)>,
        out: Output,
    );
}

impl DenseProducts for GpuDevice {
    fn column_sum(
        &self,
        plan: &mut Vec<Dispatch>,
        x: &wgpu::Buffer,
        rows: usize,
        n: usize,
        groups: Option<(&wgpu::Buffer, usize)>,
        out: Output,
    ) {
        let (group_of, count) = groups.unwrap_or((&self.empty, 1));
        if rows <= COLUMN_CHUNK {
            let (tail_at, tail, tail_off) = out
                .tail
                .map_or((0, &self.spare, 0), |t| (t.at, t.buffer, t.offset));
            let params = [
                rows,
                n,
                count,
                usize::from(out.accumulate),
                out.offset,
                0,
                tail_at,
                tail_off,
            ];
            plan.push(self.prepare(
                &COLUMN_SUM,
                &params.map(|v| v as u32),
                &[x, group_of, out.buffer, tail],
                groups_for(count * n),
            ));
            return;
        }
        let chunks = rows.div_ceil(COLUMN_CHUNK);
        let partial = self.buffer(chunks * count * n);
        let params = [rows, n, count, 0, 0, COLUMN_CHUNK, 0, 0];
        plan.push(self.prepare(
            &COLUMN_SUM,
            &params.map(|v| v as u32),
            &[x, group_of, &partial, &self.spare],
            groups_for(chunks * count * n),
        ));
        self.column_sum(plan, &partial, chunks, count * n, None, out);
    }

    fn product(
        &self,
        shape: [usize; 3],
        a: Operand,
        b: Operand,
        bias: Bias,
        activation: u32,
        c: Output,
        z: Option<&dyn Bind>,
    ) -> Dispatch {
        gemm(self, shape, a, b, bias, activation, c, z, None)
    }

    fn split_product(
        &self,
        [m, n, k]: [usize; 3],
        a: Operand,
        b: Operand,
        [k_chunk, chunks]: [usize; 2],
        c: &wgpu::Buffer,
    ) -> Dispatch {
        let out = Output::to(c, 0, n);
        gemm(
            self,
            [m, n, k],
            a,
            b,
            Bias::None,
            0,
            out,
            None,
            Some([k_chunk, chunks]),
        )
    }
}

#[allow(clippy::too_many_arguments)]
fn gemm(
    gpu: &GpuDevice,
    [m, n, k]: [usize; 3],
    a: Operand,
    b: Operand,
    bias: Bias,
    activation: u32,
    c: Output,
    z: Option<&dyn Bind>,
    split: Option<[usize; 2]>,
) -> Dispatch {
    let (bias_mode, bias_buffer, bias_off, groups) = bias.binding(gpu);
    let [k_chunk, chunks] = split.unwrap_or([0, 1]);
    let params = [
        m,
        n,
        k,
        a.offset,
        a.rows,
        a.cols,
        b.offset,
        b.rows,
        b.cols,
        c.stride,
        bias_mode,
        activation as usize,
        usize::from(c.accumulate),
        // Backward z is read, not kept.
        usize::from(z.is_some() && activation < 1 + BACKWARD),
        bias_off,
        c.offset,
        k_chunk,
        m * n,
        a.ones_row.map_or(0, |r| r + 1),
        0,
    ];
    let tiles = |v: usize| (v as u32).div_ceil(GEMM_TILE);
    gpu.prepare_grid(
        &GEMM,
        &params.map(|v| v as u32),
        &[
            a.buffer,
            b.buffer,
            bias_buffer,
            groups,
            c.buffer,
            z.unwrap_or(&gpu.spare),
        ],
        [tiles(n), tiles(m), chunks as u32],
    )
}
