//! A mixed-precision training step's dense layers (`--precision f16`): each transport layer's
//! weight is also held as f16, as stored and transposed, copied from the f32 master weights
//! after every Adam step; the activations and the gradients between layers are held as f16
//! rows in the frame path's layout (`half_layers`); every product sums in f32, on tensor cores
//! where the adapter has cooperative matrices, elsewhere on plain kernels that compute the
//! same sums (what the tests run). A layer's three products are its forward pass (`half_train`
//! with bias, activation and the pre-activation kept in f32), its input gradient dz·Wᵀ (the
//! same kernel on the transposed copy, times the activation's derivative) and its weight
//! gradient xᵀ·dz over chunks of rows (`half_weight_grad`), which also sums each chunk's dz
//! columns, the bias's gradient, in the same dispatch; the chunks are added in f32 as in an
//! f32 step. The loss's gradient is multiplied by a power
//! of two near the batch's values (`BatchBuffers::grad_scale`) so that f16 keeps the small
//! gradients, and Adam divides it back out; f16 values saturate instead of overflowing. The
//! light encoder, the hash grids and the light code's share stay in f32.

use crate::gpu::kernels::{HALF_WEIGHT_GRAD, HALF_WEIGHT_GRAD_COOP};
use crate::gpu::layers::network_layout::MlpAt;
use crate::gpu::passes::mlp_step::{row_chunks, FirstLayerBias, MlpTape, Trainable};
use crate::gpu::products::codes::{activation_code, BACKWARD};
use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::half_layers::{
    half_train_layer, held_halves, pad16, HalfLayers, HalfOut,
};
use crate::gpu::products::operands::{Bias, Output};
use nprt_gpu::{groups_for, Bind, Dispatch, GpuDevice};

/// The dispatch of xᵀ·dz, `[m, n]`, over `rows` rows cut into chunks of `chunk` rows, chunk
/// c's sums into `partial` from c · m' · n; with `bias`, m' = m + 1 and row m holds dz's
/// column sums, the bias's gradient (`half_weight_sums.wgsl`).
fn half_weight_grad(
    gpu: &GpuDevice,
    [m, n, rows]: [usize; 3],
    (x, k_pad): (&dyn Bind, usize),
    (dz, n_pad): (&wgpu::Buffer, usize),
    [chunk, chunks]: [usize; 2],
    bias: bool,
    partial: &wgpu::Buffer,
) -> Dispatch {
    let bias = usize::from(bias);
    let params = [
        rows.next_multiple_of(16),
        chunk,
        m,
        n,
        k_pad,
        n_pad,
        bias,
        0,
    ];
    let params = params.map(|v| v as u32);
    let buffers: [&dyn Bind; 3] = [x, dz, partial];
    if gpu.tensor_cores {
        // The bias's sums take a row of workgroups of their own.
        let groups = [
            n_pad.div_ceil(64) as u32,
            (k_pad.div_ceil(256) + bias) as u32,
            chunks as u32,
        ];
        gpu.prepare_grid(&HALF_WEIGHT_GRAD_COOP, &params, &buffers, groups)
    } else {
        let groups = groups_for(chunks * (m + bias) * n);
        gpu.prepare(&HALF_WEIGHT_GRAD, &params, &buffers, groups)
    }
}

impl Trainable<'_> {
    /// [`Self::mlp_backward`] in a mixed-precision step: the gradient at each layer's output
    /// as f16 rows, and as f32 rows too where `on_first` takes it; the gradient at the first
    /// layer's input into `d_input` (f32) where given. A bias's gradient is made with its
    /// weight's (`half_weight_grad`).
    pub(crate) fn half_mlp_backward(
        &self,
        plan: &mut Vec<Dispatch>,
        m: &MlpAt,
        tape: &MlpTape,
        d_last: &wgpu::Buffer,
        d_input: Option<&wgpu::Buffer>,
        on_first: Option<FirstLayerBias>,
    ) {
        let (gpu, rows) = (&self.gpu, tape.rows);
        let last = m.layers.len() - 1;
        let widest = m.widest();
        let dz16 = [0, 1].map(|_| gpu.half_buffer(held_halves(rows, widest)));
        // Only `on_first` reads a hidden layer's gradient in f32: layer 0's, here.
        let dz32 = (on_first.is_some() && last > 0).then(|| gpu.buffer(rows * widest));
        let out_width = m.layers[last].d_out;
        let d_last16 = gpu.half_buffer(held_halves(rows, out_width));
        plan.push(gpu.half_rows([rows, out_width, out_width], d_last, &d_last16));
        for (i, (layer, copies)) in m.half_layers().enumerate().rev() {
            let (g16, g32) = match i == last {
                true => (&d_last16, Some(d_last)),
                false => (&dz16[i % 2], dz32.as_ref().filter(|_| i == 0)),
            };
            let first_bias = on_first.filter(|_| i == 0);
            let x16 = match i {
                0 => tape.input16().expect("a mixed-precision tape"),
                _ => tape.hidden(i - 1),
            };
            let n_pad = pad16(layer.d_out);
            self.half_weight_gradient(
                plan,
                [copies.count, layer.d_out, rows],
                &x16,
                g16,
                layer.weight.offset + copies.row * layer.d_out,
                first_bias.is_none().then_some(layer.bias.offset),
            );
            if let Some(f) = first_bias {
                f(plan, g32.expect("layer 0's gradient in f32 for on_first"));
            }
            let pre = (i > 0).then(|| tape.pre(i - 1));
            let (derivative, out) = match (i, &pre) {
                (0, _) => match d_input {
                    Some(d) => (
                        0,
                        HalfOut {
                            z: None,
                            y16: None,
                            y32: Some(d as &dyn Bind),
                        },
                    ),
                    None => continue,
                },
                (_, pre) => (
                    activation_code(m.activation) + BACKWARD,
                    HalfOut {
                        z: pre.as_ref().map(|p| p as &dyn Bind),
                        y16: Some(&dz16[(i - 1) % 2]),
                        y32: dz32.as_ref().filter(|_| i == 1).map(|d| d as &dyn Bind),
                    },
                ),
            };
            plan.push(half_train_layer(
                gpu,
                rows,
                (g16, n_pad),
                &copies.transposed,
                Bias::None,
                derivative,
                out,
            ));
        }
    }

    /// Records a weight's gradient, `[m, n, rows]`: xᵀ·dz over the rows (f16 operands), per
    /// chunk of rows, the chunks added in order into `grads` from `offset`; with `bias` (its
    /// offset in `grads`) the bias's, dz's column sums, beside them.
    fn half_weight_gradient(
        &self,
        plan: &mut Vec<Dispatch>,
        [m, n, rows]: [usize; 3],
        x: &dyn Bind,
        dz: &wgpu::Buffer,
        offset: usize,
        bias: Option<usize>,
    ) {
        let [chunk, chunks] = row_chunks(rows.next_multiple_of(16), 16);
        let rows_of_c = m + usize::from(bias.is_some());
        let partial = self.gpu.buffer(chunks * rows_of_c * n);
        plan.push(half_weight_grad(
            self.gpu,
            [m, n, rows],
            (x, pad16(m)),
            (dz, pad16(n)),
            [chunk, chunks],
            bias.is_some(),
            &partial,
        ));
        let out = Output {
            tail: bias.map(|at| [m * n, at]),
            ..Output::to(self.grads, offset, n)
        };
        self.gpu
            .column_sum(plan, &partial, chunks, rows_of_c * n, None, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::passes::mlp_step::Trainable;
    use half::f16;

    /// A weight's gradient with its bias's folded in, against f64 sums of the same f16 values:
    /// the weight's xᵀ·dz and the bias's dz column sums, each in its own place in `grads`
    /// across chunks of rows; without the bias, its place is left alone. The sums are f32 over
    /// f16 products, so they agree to f32's rounding, far below the 10⁻² an f16 step's
    /// gradients carry (where a bias a few percent off would hide).
    #[test]
    fn a_weight_gradient_folds_its_bias_gradient_in() {
        if !GpuDevice::probe() || !GpuDevice::get().unwrap().half {
            return;
        }
        let gpu = GpuDevice::get().unwrap();
        // 20 × 24 sums over 1,000 rows: four chunks, and padded columns on both sides.
        let [m, n, rows] = [20, 24, 1000];
        let [k_pad, n_pad] = [pad16(m), pad16(n)];
        let value = |i: usize, salt: usize| ((i * 7919 + salt) % 1009) as f32 / 504.5 - 1.0;
        let held = |cols: usize, pad: usize, salt: usize| {
            let mut h = vec![0u16; held_halves(rows, cols)];
            for r in 0..rows {
                for c in 0..cols {
                    h[r * pad + c] = f16::from_f32(value(r * cols + c, salt)).to_bits();
                }
            }
            h
        };
        let (x, dz) = (held(m, k_pad, 1), held(n, n_pad, 2));
        let at =
            |h: &[u16], pad: usize, r: usize, c: usize| f64::from(f16::from_bits(h[r * pad + c]));
        let [weight, bias] = [0, m * n];
        for with_bias in [true, false] {
            let grads = gpu.upload(&vec![-1.0f32; (m + 1) * n]);
            let trainable = Trainable {
                gpu: &gpu,
                params: &gpu.spare,
                grads: &grads,
            };
            let mut plan = Vec::new();
            let [x16, dz16] = [&x, &dz].map(|h| gpu.upload(h));
            let fold = with_bias.then_some(bias);
            trainable.half_weight_gradient(&mut plan, [m, n, rows], &x16, &dz16, weight, fold);
            gpu.submit(&plan);
            let got = gpu.read(&grads, (m + 1) * n);
            for i in 0..=m {
                for j in 0..n {
                    let want = match (i == m, with_bias) {
                        (false, _) => (0..rows)
                            .map(|r| at(&x, k_pad, r, i) * at(&dz, n_pad, r, j))
                            .sum(),
                        (true, true) => (0..rows).map(|r| at(&dz, n_pad, r, j)).sum(),
                        (true, false) => -1.0,
                    };
                    let g = f64::from(got[i * n + j]);
                    assert!(
                        (g - want).abs() < 1e-4 * (1.0 + want.abs()),
                        "bias {with_bias}: ({i}, {j}) is {g}, not {want}"
                    );
                }
            }
        }
    }
}
