//! Dense layers in half precision, for the frame path's `--precision f16`: weights and
//! activations held as f16, each row padded with zeros to a multiple of 16 values, the sums
//! kept in f32 (`half_layer`). Where the adapter has cooperative matrices of 16 × 16 × 16 f16
//! products into f32 (NVIDIA's tensor cores through Vulkan) the product runs on them
//! (`half_dense_coop`); elsewhere a plain kernel computes the same sums (`half_dense`), which
//! is what the tests run on Mesa's software Vulkan. A training step's forward and input-gradient
//! products are the same product under another epilogue (`half_train_layer`: a grouped bias,
//! the pre-activation kept or the activation's derivative applied); its weight gradients are
//! `half_products`'.

use crate::gpu::kernels::{HALF_DENSE, HALF_DENSE_COOP, HALF_ROWS, HALF_TRAIN, HALF_TRAIN_COOP};
use crate::gpu::products::codes::BACKWARD;
use crate::gpu::products::operands::Bias;
use nprt_gpu::{groups_for, Bind, Dispatch, GpuDevice, KernelSource};

/// Rows a half-precision layer's workgroup covers: its inputs and outputs hold the rows up to
/// the next multiple of this.
pub const HALF_ROW_BLOCK: usize = 256;
/// Columns a workgroup covers.
const HALF_COLS: usize = 64;

/// `n` rounded up to a multiple of 16, a cooperative matrix's side.
pub fn pad16(n: usize) -> usize {
    n.next_multiple_of(16)
}

/// f16 values that `rows` rows of `cols` values take as [`Held::F16`] holds them.
pub fn held_halves(rows: usize, cols: usize) -> usize {
    rows.next_multiple_of(HALF_ROW_BLOCK) * pad16(cols)
}

/// A dense layer's weight (`d_in × d_out`, row-major) as f16 on the device, from value
/// `offset` of `buffer`: columns padded to `n_pad`, and 16 rows of zeros past the last, which a
/// product over a padded k reads. An MLP's layers share one buffer for their stored copies,
/// which its fused forward pass binds once (`half_mlp`).
pub struct HalfWeight {
    pub buffer: wgpu::Buffer,
    pub offset: usize,
    pub d_out: usize,
    pub n_pad: usize,
}

/// How rows of activations are held: f32, `d` values a row, or f16 padded with zeros to
/// `pad16(d)` values a row and to the next multiple of [`HALF_ROW_BLOCK`] rows (a
/// half-precision layer's input, and its output where another layer reads it).
#[derive(Clone, Copy)]
pub enum Held<'a> {
    F32(&'a wgpu::Buffer),
    F16(&'a wgpu::Buffer),
}

/// f16 values a `d_in × d_out` weight takes as [`HalfWeight`] holds it: `d_in + 16` rows of
/// `pad16(d_out)`.
pub fn half_weight_halves(d_in: usize, d_out: usize) -> usize {
    (d_in + 16) * pad16(d_out)
}

/// `weight` (`d_in × d_out`, row-major) as the f16 bits [`HalfWeight`] holds: `d_in + 16` rows
/// of `pad16(d_out)` values, zeros past the weight's (what `nprt export` writes too).
pub fn half_weight_bits(weight: &[f32], d_in: usize, d_out: usize) -> Vec<u16> {
    let n_pad = pad16(d_out);
    let mut padded = vec![0u16; half_weight_halves(d_in, d_out)];
    for (row, values) in padded.chunks_mut(n_pad).zip(weight.chunks(d_out)) {
        for (h, &v) in row.iter_mut().zip(values) {
            *h = half::f16::from_f32(v).to_bits();
        }
    }
    padded
}

/// The half-precision dense layers on the device: f16 weights and rows, and their products.
pub trait HalfLayers {
    /// `[d_in, d_out]` weights one after another in one buffer, each in the layout
    /// [`HalfWeight`] describes, zero (the frame path and a mixed-precision training step copy
    /// their weights in on the device).
    fn half_weights(&self, shapes: &[[usize; 2]]) -> Vec<HalfWeight>;

    /// The dispatch that writes `rows` rows of `cols` f32 values of `src` (row stride
    /// `stride`) to `dst` as f16 rows of `pad16(cols)` values, zeros in the padding and in the
    /// rows up to the next multiple of [`HALF_ROW_BLOCK`].
    fn half_rows(&self, shape: [usize; 3], src: &wgpu::Buffer, dst: &dyn Bind) -> Dispatch;

    /// The dispatch of one half-precision dense layer, `act(x·W[w_row..] + bias)` over `rows`
    /// rows of `x` (f16 rows of `k_pad` values, a multiple of 16, held up to the next multiple
    /// of [`HALF_ROW_BLOCK`] rows), `activation` 0 linear, 1 ReLU, 2 SIREN.
    #[allow(clippy::too_many_arguments)]
    fn half_layer(
        &self,
        rows: usize,
        x: &wgpu::Buffer,
        k_pad: usize,
        w: &HalfWeight,
        w_row: usize,
        bias: &dyn Bind,
        activation: u32,
        y: Held,
    ) -> Dispatch;
}

impl HalfLayers for GpuDevice {
    fn half_weights(&self, shapes: &[[usize; 2]]) -> Vec<HalfWeight> {
        let sizes = shapes
            .iter()
            .map(|&[d_in, d_out]| half_weight_halves(d_in, d_out));
        let buffer = self.half_buffer(sizes.clone().sum());
        let mut offset = 0;
        (shapes.iter().zip(sizes))
            .map(|(&[_, d_out], size)| {
                offset += size;
                HalfWeight {
                    buffer: buffer.clone(),
                    offset: offset - size,
                    d_out,
                    n_pad: pad16(d_out),
                }
            })
            .collect()
    }

    fn half_rows(
        &self,
        [rows, cols, stride]: [usize; 3],
        src: &wgpu::Buffer,
        dst: &dyn Bind,
    ) -> Dispatch {
        let padded = rows.next_multiple_of(HALF_ROW_BLOCK);
        let k_pad = pad16(cols);
        // Offset 0 and column stride 1: export version 3 documents both for engines.
        let params = [rows, padded, cols, stride, k_pad, 0, 1, 0].map(|v| v as u32);
        let groups = groups_for(padded * k_pad);
        self.prepare(&HALF_ROWS, &params, &[src, dst], groups)
    }

    fn half_layer(
        &self,
        rows: usize,
        x: &wgpu::Buffer,
        k_pad: usize,
        w: &HalfWeight,
        w_row: usize,
        bias: &dyn Bind,
        activation: u32,
        y: Held,
    ) -> Dispatch {
        let (y16, y32, half_out) = match y {
            Held::F16(b) => (b, &self.spare, 1),
            Held::F32(b) => (&self.spare, b, 0),
        };
        let params = [
            rows,
            w.d_out,
            w.n_pad,
            k_pad,
            w.offset + w_row * w.n_pad,
            activation as usize,
            half_out,
            0,
        ]
        .map(|v| v as u32);
        half_dense(
            self,
            [&HALF_DENSE, &HALF_DENSE_COOP],
            &params,
            &[x, &w.buffer, bias, y16, y32],
            [rows, w.n_pad],
        )
    }
}

/// The dispatch of a half-precision dense product (`half_dense`'s main, or on tensor cores
/// `half_dense_coop`'s: the first or second of `kernels`, each under its epilogue) over
/// `rows` rows and `n_pad` output columns, with the epilogue's `params` and `buffers`.
fn half_dense(
    gpu: &GpuDevice,
    [plain, coop]: [&KernelSource; 2],
    params: &[u32],
    buffers: &[&dyn Bind],
    [rows, n_pad]: [usize; 2],
) -> Dispatch {
    let kernel = if gpu.tensor_cores { coop } else { plain };
    let groups = [
        n_pad.div_ceil(HALF_COLS) as u32,
        rows.div_ceil(HALF_ROW_BLOCK) as u32,
    ];
    gpu.prepare(kernel, params, buffers, groups)
}

/// Where a mixed-precision product's results go.
pub struct HalfOut<'a> {
    /// The pre-activation: kept here by a forward product, read for the activation's
    /// derivative by a backward one.
    pub z: Option<&'a dyn Bind>,
    /// f16 rows padded as `half_layers` holds them (the next product's operand).
    pub y16: Option<&'a dyn Bind>,
    /// f32 rows of the layer's width.
    pub y32: Option<&'a dyn Bind>,
}

/// The dispatch of `act(x·W + bias)` over `rows` rows of `x` (f16 rows of `k_pad` values)
/// with `w` from its first row; `activation` 3 or 4 multiplies by ReLU's or SIREN's
/// derivative at `out.z` instead (`half_train_layer.wgsl`).
pub fn half_train_layer(
    gpu: &GpuDevice,
    rows: usize,
    (x, k_pad): (&dyn Bind, usize),
    w: &HalfWeight,
    bias: Bias,
    activation: u32,
    out: HalfOut,
) -> Dispatch {
    let (bias_mode, bias_buffer, bias_off, group_of) = bias.binding(gpu);
    let keep_z = out.z.is_some() && activation < 1 + BACKWARD;
    let params = [
        rows,
        w.d_out,
        w.n_pad,
        k_pad,
        w.offset,
        activation as usize,
        bias_mode,
        bias_off,
        usize::from(keep_z),
        usize::from(out.y16.is_some()),
        usize::from(out.y32.is_some()),
        0,
    ]
    .map(|v| v as u32);
    half_dense(
        gpu,
        [&HALF_TRAIN, &HALF_TRAIN_COOP],
        &params,
        &[
            x,
            &w.buffer,
            bias_buffer,
            group_of,
            out.z.unwrap_or(&gpu.spare),
            out.y16.unwrap_or(&gpu.spare),
            out.y32.unwrap_or(&gpu.spare),
        ],
        [rows, w.n_pad],
    )
}
