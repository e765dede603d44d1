//! A mixed-precision training step's dense layers (`--precision f16`): each transport layer's
//! weight is also held as f16, as stored and transposed, copied from the f32 master weights
//! after every Adam step; the activations and the gradients between layers are held as f16
//! rows in the frame path's layout (`half_layers`); every product sums in f32, on tensor cores
//! where the adapter has cooperative matrices, elsewhere on plain kernels that compute the
//! same sums (what the tests run). A layer's three products are its forward pass (`half_train`
//! with bias, activation and the pre-activation kept in f32), its input gradient dz·Wᵀ (the
//! same kernel on the transposed copy, times the activation's derivative) and its weight
//! gradient xᵀ·dz over chunks of rows (`half_weight_grad`), whose chunks and the biases'
//! gradients are added in f32 as in an f32 step. The loss's gradient is multiplied by a power
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
/// c's sums into `partial` from c · m · n (`half_weight_sums.wgsl`).
fn half_weight_grad(
    gpu: &GpuDevice,
    [m, n, rows]: [usize; 3],
    (x, k_pad): (&wgpu::Buffer, usize),
    (dz, n_pad): (&wgpu::Buffer, usize),
    [chunk, chunks]: [usize; 2],
    partial: &wgpu::Buffer,
) -> Dispatch {
    let params = [rows.next_multiple_of(16), chunk, m, n, k_pad, n_pad, 0, 0].map(|v| v as u32);
    let buffers: [&dyn Bind; 3] = [x, dz, partial];
    if gpu.tensor_cores {
        let groups = [
            n_pad.div_ceil(64) as u32,
            k_pad.div_ceil(256) as u32,
            chunks as u32,
        ];
        gpu.prepare_grid(&HALF_WEIGHT_GRAD_COOP, &params, &buffers, groups)
    } else {
        let groups = groups_for(chunks * m * n);
        gpu.prepare(&HALF_WEIGHT_GRAD, &params, &buffers, groups)
    }
}

impl Trainable<'_> {
    /// [`Self::mlp_backward`] in a mixed-precision step: the gradient at each layer's output
    /// as f16 rows for the products and as f32 rows for the bias's gradient (and `on_first`),
    /// the gradient at the first layer's input into `d_input` (f32) where given.
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
        let dz32 = [0, 1].map(|_| gpu.buffer(rows * widest));
        let out_width = m.layers[last].d_out;
        let d_last16 = gpu.half_buffer(held_halves(rows, out_width));
        plan.push(gpu.half_rows([rows, out_width, out_width], d_last, &d_last16));
        for (i, (layer, copies)) in m.half_layers().enumerate().rev() {
            let (g16, g32) = match i == last {
                true => (&d_last16, d_last),
                false => (&dz16[i % 2], &dz32[i % 2]),
            };
            let x16 = match i {
                0 => tape.input16.as_ref().expect("a mixed-precision tape"),
                _ => &tape.outputs[i - 1],
            };
            let n_pad = pad16(layer.d_out);
            self.half_weight_gradient(
                plan,
                [copies.count, layer.d_out, rows],
                x16,
                g16,
                layer.weight.offset + copies.row * layer.d_out,
            );
            match on_first.filter(|_| i == 0) {
                Some(f) => f(plan, g32),
                None => self.gpu.column_sum(
                    plan,
                    g32,
                    rows,
                    layer.d_out,
                    None,
                    Output::to(self.grads, layer.bias.offset, layer.d_out),
                ),
            }
            let (derivative, out) = match i {
                0 => match d_input {
                    Some(d) => (
                        0,
                        HalfOut {
                            z: None,
                            y16: None,
                            y32: Some(d),
                        },
                    ),
                    None => continue,
                },
                _ => (
                    activation_code(m.activation) + BACKWARD,
                    HalfOut {
                        z: Some(&tape.pre[i - 1]),
                        y16: Some(&dz16[(i - 1) % 2]),
                        y32: Some(&dz32[(i - 1) % 2]),
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
    /// chunk of rows, the chunks added in order into `grads` from `offset`.
    fn half_weight_gradient(
        &self,
        plan: &mut Vec<Dispatch>,
        [m, n, rows]: [usize; 3],
        x: &wgpu::Buffer,
        dz: &wgpu::Buffer,
        offset: usize,
    ) {
        let [chunk, chunks] = row_chunks(rows.next_multiple_of(16), 16);
        let partial = self.gpu.buffer(chunks * m * n);
        plan.push(half_weight_grad(
            self.gpu,
            [m, n, rows],
            (x, pad16(m)),
            (dz, pad16(n)),
            [chunk, chunks],
            &partial,
        ));
        self.gpu.column_sum(
            plan,
            &partial,
            chunks,
            m * n,
            None,
            Output::to(self.grads, offset, n),
        );
    }
}
