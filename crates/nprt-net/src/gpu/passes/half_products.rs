//! A mixed-precision training step's dense layers (`--precision f16`): each transport layer's
//! weight is also held as f16, as stored and transposed, copied from the f32 master weights
//! after every Adam step; the activations and the gradients between layers are held as f16
//! rows in the frame path's layout (`half_layers`); every product sums in f32, on tensor cores
//! where the adapter has cooperative matrices, elsewhere on plain kernels that compute the
//! same sums (what the tests run). A layer's three products are its forward pass (with bias,
//! activation and the pre-activation kept in f32), its input gradient dz·Wᵀ (on the transposed
//! copy, times the activation's derivative) and its weight gradient xᵀ·dz over chunks of rows
//! (`half_weight_grad`), which also sums each chunk's dz columns, the bias's gradient, in the
//! same dispatch; the chunks are added in f32 as in an f32 step. An MLP's forward passes, and
//! its input gradients down to its first layer's output, each take one dispatch where the
//! fused pass holds the MLP (`half_mlp`), else a dispatch a layer (`half_train`). The loss's
//! gradient is multiplied by a power
//! of two near the batch's values (`BatchBuffers::grad_scale`) so that f16 keeps the small
//! gradients, and Adam divides it back out; f16 values saturate instead of overflowing. The
//! light encoder, the hash grids and the light code's share stay in f32.

use crate::gpu::kernels::{HALF_WEIGHT_GRAD, HALF_WEIGHT_GRAD_COOP};
use crate::gpu::layers::mlp_tape::{held_rows, HeldRows, MlpTape};
use crate::gpu::layers::network_layout::MlpAt;
use crate::gpu::passes::mlp_step::{row_chunks, FirstLayerBias, Trainable};
use crate::gpu::products::codes::{activation_code, BACKWARD};
use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::half_layers::{
    half_train_layer, held_halves, pad16, HalfLayers, HalfOut, Held,
};
use crate::gpu::products::half_mlp::{fits, half_mlp, FusedIo, FusedLayer};
use crate::gpu::products::operands::{Bias, Output};
use nprt_gpu::{groups_for, Bind, Dispatch, GpuDevice};

/// The dispatch of xᵀ·dz, `[m, n]`, over `rows` rows cut into chunks of `chunk` rows, chunk
/// c's sums into `partial` from c · m' · n; with `bias`, m' = m + 1 and row m holds dz's
/// column sums, the bias's gradient (`half_weight_sums.wgsl`).
fn half_weight_grad(
    gpu: &GpuDevice,
    [m, n, rows]: [usize; 3],
    (x, k_pad): (&dyn Bind, usize),
    (dz, n_pad): (&dyn Bind, usize),
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
        // 4 × 4 sums a thread.
        let groups = groups_for(chunks * (m + bias).div_ceil(4) * n.div_ceil(4));
        gpu.prepare(&HALF_WEIGHT_GRAD, &params, &buffers, groups)
    }
}

impl Trainable<'_> {
    /// [`Self::mlp_backward`] in a mixed-precision step: the gradient at each layer's
    /// pre-activation (`layer_gradients`), then each weight's gradient with its bias's
    /// (`half_weight_grad`), and the gradient at the first layer's input into `d_input` (f32)
    /// where given.
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
        let (dz, dz32) = self.layer_gradients(plan, m, tape, d_last, on_first.is_some());
        for (i, (layer, copies)) in m.half_layers().enumerate().rev() {
            let x16 = match i {
                0 => tape.input16().expect("a mixed-precision tape"),
                _ => tape.hidden(i - 1),
            };
            let first_bias = on_first.is_some() && i == 0;
            self.half_weight_gradient(
                plan,
                [copies.count, layer.d_out, rows],
                &x16,
                &dz.part(i),
                layer.weight.offset + copies.row * layer.d_out,
                (!first_bias).then_some(layer.bias.offset),
            );
        }
        if let Some(f) = on_first {
            f(plan, dz32.as_ref().unwrap_or(d_last));
        }
        if let Some(d) = d_input {
            let (layer, copies) = (&m.layers[0], &m.half[0]);
            let out = HalfOut {
                z: None,
                y16: None,
                y32: Some(d),
            };
            let g = (&dz.part(0) as &dyn Bind, pad16(layer.d_out));
            let t = &copies.transposed;
            plan.push(half_train_layer(gpu, rows, g, t, Bias::None, 0, out));
        }
    }

    /// The gradient at each layer's pre-activation as f16 rows, from `d_last` at the output
    /// down (each layer's input gradient on its transposed weight, times the activation's
    /// derivative at the pre-activation below): in one dispatch where the fused pass holds the
    /// transposed layers (`half_mlp`), else a layer a dispatch. With `f32_first`, layer 0's as
    /// f32 rows too (`d_last` itself for a single layer).
    fn layer_gradients(
        &self,
        plan: &mut Vec<Dispatch>,
        m: &MlpAt,
        tape: &MlpTape,
        d_last: &wgpu::Buffer,
        f32_first: bool,
    ) -> (HeldRows, Option<wgpu::Buffer>) {
        let (gpu, rows) = (&self.gpu, tape.rows);
        let last = m.layers.len() - 1;
        let layers: Vec<_> = m.half_layers().collect();
        let derivative = activation_code(m.activation) + BACKWARD;
        let mut stages: Vec<FusedLayer> = (1..=last)
            .rev()
            .map(|i| FusedLayer {
                weight: &layers[i].1.transposed,
                k_pad: pad16(layers[i].0.d_out),
                bias_at: 0,
                activation: derivative,
                held_at: 0,
                pre_at: tape.pre(i - 1).span.offset,
            })
            .collect();
        let fused = last > 0 && fits(gpu, &stages);
        let words = layers.iter().map(|(l, _)| held_halves(rows, l.d_out) / 2);
        let dz = held_rows(gpu, words, fused);
        let dz32 = (f32_first && last > 0).then(|| gpu.buffer(rows * layers[0].0.d_out));
        let out_width = layers[last].0.d_out;
        if fused {
            for (stage, i) in stages.iter_mut().zip((1..=last).rev()) {
                stage.held_at = 2 * dz.part(i - 1).span.offset;
            }
            let io = FusedIo {
                rows,
                x: Held::F32(d_last),
                x_cols: out_width,
                bias0: Bias::None,
                biases: None,
                y16: Some(dz.part(0).buffer),
                out16: true,
                kept_input: Some(2 * dz.part(last).span.offset),
                y32: dz32.as_ref(),
                pre: Some((tape.pre(0).buffer, false)),
            };
            plan.push(half_mlp(gpu, &stages, &io));
            return (dz, dz32);
        }
        plan.push(gpu.half_rows([rows, out_width, out_width], d_last, &dz.part(last)));
        for i in (1..=last).rev() {
            let pre = tape.pre(i - 1);
            let out = HalfOut {
                z: Some(&pre),
                y16: Some(&dz.part(i - 1)),
                y32: dz32.as_ref().filter(|_| i == 1).map(|d| d as &dyn Bind),
            };
            let (layer, copies) = layers[i];
            let g = (&dz.part(i) as &dyn Bind, pad16(layer.d_out));
            let t = &copies.transposed;
            plan.push(half_train_layer(
                gpu,
                rows,
                g,
                t,
                Bias::None,
                derivative,
                out,
            ));
        }
        (dz, dz32)
    }

    /// Records a weight's gradient, `[m, n, rows]`: xᵀ·dz over the rows (f16 operands), per
    /// chunk of rows, the chunks added in order into `grads` from `offset`; with `bias` (its
    /// offset in `grads`) the bias's, dz's column sums, beside them.
    fn half_weight_gradient(
        &self,
        plan: &mut Vec<Dispatch>,
        [m, n, rows]: [usize; 3],
        x: &dyn Bind,
        dz: &dyn Bind,
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
