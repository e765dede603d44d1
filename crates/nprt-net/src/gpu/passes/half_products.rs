//! A mixed-precision training step's dense layers (`--precision f16`): each transport layer's
//! weight is also held as f16, as stored and transposed, copied from the f32 master weights
//! after every Adam step (an MLP's layers in one dispatch); the activations and the gradients
//! between layers are held as f16 rows in the frame path's layout (`half_layers`); every
//! product sums in f32, on tensor cores where the adapter has cooperative matrices, elsewhere
//! on plain kernels that compute the same sums (what the tests run). A layer's three products
//! are its forward pass (with bias, activation and the pre-activation kept in f32), its input
//! gradient dz·Wᵀ (on the transposed copy, times the activation's derivative) and its weight
//! gradient xᵀ·dz over chunks of rows, which also sums each chunk's dz columns, the bias's
//! gradient. An MLP's forward pass, and its input gradients from the last layer down to the
//! first layer's input, each take one dispatch where the fused pass holds the MLP
//! (`half_mlp`), else a dispatch a layer (`half_train`); its weight gradients one more
//! (`half_weight_grad`, every layer's chunks into one block laid out as the parameters), and
//! one column sum adds the chunks in f32, as in an f32 step. The loss's gradient is multiplied
//! by a power of two near the batch's values (`BatchBuffers::grad_scale`) so that f16 keeps
//! the small gradients, and Adam divides it back out; f16 values saturate instead of
//! overflowing. The light encoder, the hash grids and the light code's share stay in f32.

use crate::gpu::kernels::{HALF_WEIGHT_GRAD, HALF_WEIGHT_GRAD_COOP};
use crate::gpu::layers::chunk_sums::ChunkSums;
use crate::gpu::layers::mlp_tape::{held_rows, HeldRows, MlpTape};
use crate::gpu::layers::network_layout::MlpAt;
use crate::gpu::passes::mlp_step::{row_chunks, Trainable, ViewSums};
use crate::gpu::products::codes::{activation_code, BACKWARD};
use crate::gpu::products::half_layers::{
    half_train_layer, held_halves, pad16, HalfLayers, HalfOut, Held,
};
use crate::gpu::products::half_mlp::{fits, half_mlp, FusedIo, FusedLayer, Pre};
use crate::gpu::products::operands::Bias;
use nprt_gpu::{groups_for, Bind, Dispatch, GpuDevice, Part};

/// What an MLP's backward pass leaves for its weight gradients: each layer's gradient at its
/// pre-activation as f16 rows (`dz`), and whether the gradient at the first layer's input is
/// made too (`to_input`).
struct LayerGradients {
    dz: HeldRows,
    to_input: bool,
}

/// Layers a weight-gradient dispatch takes at most (`half_weight_sums.wgsl`'s tables).
const GRAD_LAYERS: usize = 8;

/// One layer of a weight-gradient pass: the gradient's `[m, n]`, its x rows and dz rows (f16,
/// padded to 16 values a row, as [`Held::F16`] holds them), where its weight's sums and, with
/// a bias, its bias's start in a chunk's block, and with `views` (and a bias) dz's sums per
/// view too.
pub(crate) struct GradLayer<'a> {
    pub shape: [usize; 2],
    pub x: Part<'a>,
    pub dz: Part<'a>,
    pub w_at: usize,
    pub b_at: Option<usize>,
    pub views: Option<PerView<'a>>,
}

/// A weight-gradient pass's sums per view: each batch row's view and the views' number. They
/// end a chunk's block, past the parameters' span (`n` a view).
#[derive(Clone, Copy)]
pub(crate) struct PerView<'a> {
    pub view: &'a wgpu::Buffer,
    pub count: usize,
}

/// The dispatches of `layers`' weight gradients, xᵀ·dz over `rows` rows cut into chunks of
/// `chunk`, chunk c's sums into `partial` from c · stride, each layer's at its places
/// (`half_weight_sums.wgsl`): one dispatch for up to [`GRAD_LAYERS`] consecutive layers whose x
/// rows lie in one buffer and dz rows in another (a fused pass's), and whose sums per view,
/// if any, read one buffer of views, else a dispatch a layer.
fn half_weight_grads(
    gpu: &GpuDevice,
    layers: &[GradLayer],
    rows: usize,
    [chunk, chunks, stride]: [usize; 3],
    partial: &wgpu::Buffer,
) -> Vec<Dispatch> {
    fn view<'a>(l: &GradLayer<'a>) -> Option<&'a wgpu::Buffer> {
        l.views.map(|v| v.view)
    }
    let shared = |a: &GradLayer, b: &GradLayer| {
        let views = view(a).is_none() || view(b).is_none() || view(a) == view(b);
        a.x.buffer == b.x.buffer && a.dz.buffer == b.dz.buffer && views
    };
    (layers.chunk_by(shared))
        .flat_map(|run| run.chunks(GRAD_LAYERS))
        .map(|group| {
            let mut shape = [[0; 4]; GRAD_LAYERS];
            let mut at = [[0; 4]; GRAD_LAYERS];
            let mut work = [[0; 4]; GRAD_LAYERS + 1];
            let (mut items, mut most) = (0, 0);
            for (i, l) in group.iter().enumerate() {
                let [m, n] = l.shape;
                let [k_pad, n_pad] = [pad16(m), pad16(n)];
                let bias = usize::from(l.b_at.is_some());
                assert!(
                    l.views.is_none() || l.b_at.is_some(),
                    "view sums with a bias"
                );
                let views = l.views.map_or(0, |v| v.count);
                let g_at = stride - views * n;
                shape[i] = [m, n, k_pad, n_pad];
                let [x_at, dz_at] = [&l.x, &l.dz].map(|rows| 2 * rows.span.offset);
                at[i] = [x_at, dz_at, l.w_at, l.b_at.unwrap_or(0)];
                work[i] = [items, bias, views, g_at];
                // A plain thread's 4 × 4 sums; a tensor-core workgroup's 256 × 64 (and a row
                // of them for the bias and each view), a row of workgroups a layer.
                let sum_rows = bias + views;
                items += (m + sum_rows).div_ceil(4) * n.div_ceil(4);
                most = most.max(n_pad.div_ceil(64) * (k_pad.div_ceil(256) + sum_rows));
            }
            work[group.len()][0] = items;
            let mut params = vec![rows.next_multiple_of(16), chunk, group.len(), stride];
            params.extend(shape.iter().chain(&at).chain(&work).flatten());
            let params: Vec<u32> = params.iter().map(|&v| v as u32).collect();
            let views = group.iter().find_map(view).unwrap_or(&gpu.empty);
            let buffers: [&dyn Bind; 4] = [group[0].x.buffer, group[0].dz.buffer, partial, views];
            match gpu.tensor_cores {
                true => gpu.prepare_grid(
                    &HALF_WEIGHT_GRAD_COOP,
                    &params,
                    &buffers,
                    [most, group.len(), chunks].map(|v| v as u32),
                ),
                false => gpu.prepare(
                    &HALF_WEIGHT_GRAD,
                    &params,
                    &buffers,
                    groups_for(chunks * items),
                ),
            }
        })
        .collect()
}

impl Trainable<'_> {
    /// [`Self::mlp_backward`] in a mixed-precision step: the gradient at each layer's
    /// pre-activation (`layer_gradients`), then every weight's gradient with its bias's and
    /// the sums per view where asked (`half_weight_gradients`), and the gradient at the first
    /// layer's input into `d_input` (f32) where given.
    pub(crate) fn half_mlp_backward(
        &self,
        plan: &mut Vec<Dispatch>,
        m: &MlpAt,
        tape: &MlpTape,
        d_last: &wgpu::Buffer,
        d_input: Option<&wgpu::Buffer>,
        view_sums: Option<&ViewSums>,
    ) {
        let (gpu, rows) = (&self.gpu, tape.rows);
        let LayerGradients { dz, to_input } = self.layer_gradients(plan, m, tape, d_last, d_input);
        // The MLP's tensors lie in the parameters one after another, the first weight's first;
        // the sums per view come after them in a chunk's block.
        let base = m.layers[0].weight.offset;
        let last = &m.layers[m.layers.len() - 1].bias;
        let len = last.offset + last.len - base;
        let layers: Vec<GradLayer> = (m.half_layers().enumerate())
            .map(|(i, (layer, copies))| GradLayer {
                shape: [copies.count, layer.d_out],
                x: match i {
                    0 => tape.input16().expect("a mixed-precision tape"),
                    _ => tape.hidden(i - 1),
                },
                dz: dz.part(i),
                w_at: layer.weight.offset + copies.row * layer.d_out - base,
                b_at: Some(layer.bias.offset - base),
                views: view_sums.filter(|_| i == 0).map(|v| PerView {
                    view: v.view,
                    count: v.views,
                }),
            })
            .collect();
        let d_views = view_sums.map(|v| v.d_views);
        self.half_weight_gradients(plan, &layers, rows, [base, len], d_views);
        if let Some(v) = view_sums {
            (v.then)(plan);
        }
        if let Some(d) = d_input.filter(|_| !to_input) {
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
    /// transposed layers (`half_mlp`), which then also goes on to the gradient at the first
    /// layer's input, into `d_input`, where given and it holds that layer too; else a layer a
    /// dispatch.
    fn layer_gradients(
        &self,
        plan: &mut Vec<Dispatch>,
        m: &MlpAt,
        tape: &MlpTape,
        d_last: &wgpu::Buffer,
        d_input: Option<&wgpu::Buffer>,
    ) -> LayerGradients {
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
        // The first layer's input gradient as one more stage, linear, where the pass holds it.
        let mut to_input = None;
        if let (true, Some(d)) = (fused, d_input) {
            stages.push(FusedLayer {
                weight: &layers[0].1.transposed,
                k_pad: pad16(layers[0].0.d_out),
                bias_at: 0,
                activation: 0,
                held_at: 0,
                pre_at: 0,
            });
            match fits(gpu, &stages) {
                true => to_input = Some(d),
                false => drop(stages.pop()),
            }
        }
        let words = layers.iter().map(|(l, _)| held_halves(rows, l.d_out) / 2);
        let dz = held_rows(gpu, words, fused);
        if fused {
            let out_width = layers[last].0.d_out;
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
                out16: to_input.is_none(),
                kept_input: Some(2 * dz.part(last).span.offset),
                y32: to_input,
                pre: Some((tape.pre(0).buffer, Pre::Derive)),
            };
            plan.push(half_mlp(gpu, &stages, &io));
            return LayerGradients {
                dz,
                to_input: to_input.is_some(),
            };
        }
        self.layer_gradients_apart(plan, m, tape, d_last, &dz);
        LayerGradients {
            dz,
            to_input: false,
        }
    }

    /// [`Self::layer_gradients`] a layer a dispatch (`half_train`), where the fused pass cannot
    /// hold the MLP: into `dz`'s rows.
    fn layer_gradients_apart(
        &self,
        plan: &mut Vec<Dispatch>,
        m: &MlpAt,
        tape: &MlpTape,
        d_last: &wgpu::Buffer,
        dz: &HeldRows,
    ) {
        let (gpu, rows) = (&self.gpu, tape.rows);
        let last = m.layers.len() - 1;
        let out_width = m.layers[last].d_out;
        let derivative = activation_code(m.activation) + BACKWARD;
        plan.push(gpu.half_rows([rows, out_width, out_width], d_last, &dz.part(last)));
        for (i, (layer, copies)) in m.half_layers().enumerate().skip(1).rev() {
            let pre = tape.pre(i - 1);
            let out = HalfOut {
                z: Some(&pre),
                y16: Some(&dz.part(i - 1)),
                y32: None,
            };
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
    }

    /// Records `layers`' weight gradients over `rows` rows into `grads[at..at + len]`, the
    /// span their places (each layer's `w_at` and `b_at`) are counted from: xᵀ·dz (f16
    /// operands) per chunk of rows (`half_weight_grads`), then one column sum adds the chunks
    /// in order over the whole span, and a layer's sums per view (at most one layer's, past
    /// the span in a chunk's block) into `d_views`. What no layer's sums take in the span (a
    /// first layer's rows of the light code, a bias left out, the gaps between tensors) it
    /// writes as zeros, for the light code's products to overwrite after.
    fn half_weight_gradients(
        &self,
        plan: &mut Vec<Dispatch>,
        layers: &[GradLayer],
        rows: usize,
        [at, len]: [usize; 2],
        d_views: Option<&wgpu::Buffer>,
    ) {
        let mut extra = 0;
        for l in layers {
            let [m, n] = l.shape;
            assert!(l.w_at + m * n <= len && l.b_at.is_none_or(|b| b + n <= len));
            if let Some(v) = l.views {
                assert_eq!(extra, 0, "one layer's sums per view");
                extra = v.count * n;
            }
        }
        let [chunk, chunks] = row_chunks(rows.next_multiple_of(16), 16);
        let sums = ChunkSums::new(self.gpu, [at, len, extra], chunks);
        let split = [chunk, chunks, sums.stride];
        plan.extend(half_weight_grads(self.gpu, layers, rows, split, &sums.sums));
        sums.record_total(self.gpu, plan, self.grads, d_views);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::passes::mlp_step::Trainable;
    use half::f16;
    use nprt_gpu::Span;

    /// Three layers' weight gradients with their biases folded in, against f64 sums of the
    /// same f16 values: two layers whose rows share an x buffer and a dz buffer (as a fused
    /// pass keeps them) in one dispatch, a third (with no bias) in buffers of its own in
    /// another, and one column sum over the span they lie in. Each weight's xᵀ·dz and each
    /// bias's dz column sums land in their own places, across chunks of rows, and the first
    /// layer's dz column sums per view in a buffer of their own; what no sums take in the
    /// span (the third bias, the gaps) is zero, and nothing outside it is touched. The sums
    /// are f32 over f16 products, so they agree to f32's rounding, far below the 10⁻² an f16
    /// step's gradients carry (where a bias a few percent off would hide).
    #[test]
    fn an_mlps_weight_gradients_come_from_one_dispatch_with_their_biases_and_view_sums() {
        if !GpuDevice::probe() || !GpuDevice::get().unwrap().half {
            return;
        }
        let gpu = GpuDevice::get().unwrap();
        let rows = 1000;
        // [m, n] and whether a bias: padded columns on both sides; over 1,000 rows, 4 chunks.
        let shapes = [([20, 24], true), ([24, 3], true), ([40, 17], false)];
        let value = |i: usize, salt: usize| ((i * 7919 + salt) % 1009) as f32 / 504.5 - 1.0;
        let held = |cols: usize, salt: usize| {
            let pad = pad16(cols);
            let mut h = vec![0u16; held_halves(rows, cols)];
            for r in 0..rows {
                for c in 0..cols {
                    h[r * pad + c] = f16::from_f32(value(r * cols + c, salt)).to_bits();
                }
            }
            h
        };
        let hosts: Vec<[Vec<u16>; 2]> = (shapes.iter().enumerate())
            .map(|(l, ([m, n], _))| [held(*m, 2 * l), held(*n, 2 * l + 1)])
            .collect();
        // The first two layers' x rows in one buffer, their dz rows in another, each at a
        // binding-aligned offset; the third's alone.
        let align = gpu.binding_alignment();
        let shared = |which: usize| {
            let mut words: Vec<u32> = Vec::new();
            let mut spans = Vec::new();
            for h in &hosts[..2] {
                let offset = words.len().next_multiple_of(align);
                words.resize(offset, 0);
                words.extend(bytemuck::cast_slice::<u16, u32>(&h[which]));
                spans.push(Span {
                    offset,
                    len: h[which].len() / 2,
                });
            }
            (gpu.upload(&words), spans)
        };
        let [(x01, x_spans), (dz01, dz_spans)] = [0, 1].map(shared);
        let [x2, dz2] = [0, 1].map(|w| gpu.upload(&hosts[2][w]));
        let part = |buffer, span| Part { buffer, span };
        let own = |h: &Vec<u16>| Span {
            offset: 0,
            len: h.len() / 2,
        };
        let rows_of = [
            (part(&x01, x_spans[0]), part(&dz01, dz_spans[0])),
            (part(&x01, x_spans[1]), part(&dz01, dz_spans[1])),
            (part(&x2, own(&hosts[2][0])), part(&dz2, own(&hosts[2][1]))),
        ];
        // The tensors' places in the span as a parameter layout has them: a gap of 5 before
        // each.
        let mut end = 0;
        let mut place = |len: usize| {
            end += 5 + len;
            end - len
        };
        let mut layers = Vec::new();
        for (&([m, n], bias), (x, dz)) in shapes.iter().zip(rows_of) {
            let w_at = place(m * n);
            let b_at = place(n);
            layers.push(GradLayer {
                shape: [m, n],
                x,
                dz,
                w_at,
                b_at: bias.then_some(b_at),
                views: None,
            });
        }
        let [at, len] = [7, end];
        // The first layer's sums per view too: 3 views, the rows' taking turns unevenly.
        let (views, view_of) = (3, |r: usize| (r * r / 7 % 3) as u32);
        let view = gpu.upload(&(0..rows).map(view_of).collect::<Vec<u32>>());
        layers[0].views = Some(PerView {
            view: &view,
            count: views,
        });
        let n0 = layers[0].shape[1];
        let d_views = gpu.upload(&vec![-1.0f32; views * n0 + 7]);
        let grads = gpu.upload(&vec![-1.0f32; at + len + 7]);
        let trainable = Trainable {
            gpu: &gpu,
            params: &gpu.spare,
            grads: &grads,
        };
        let mut plan = Vec::new();
        trainable.half_weight_gradients(&mut plan, &layers, rows, [at, len], Some(&d_views));
        assert_eq!(plan.len(), 3, "two products and a column sum");
        gpu.submit(&plan);
        let mut got = gpu.read(&grads, at + len + 7);
        got.extend(gpu.read(&d_views, views * n0 + 7));
        let mut want = vec![-1.0f64; at + len + 7];
        want[at..at + len].fill(0.0);
        for (l, layer) in layers.iter().enumerate() {
            let [m, n] = layer.shape;
            let [x, dz] = &hosts[l];
            let value = |h: &[u16], cols: usize, r: usize, c: usize| {
                f64::from(f16::from_bits(h[r * pad16(cols) + c]))
            };
            for i in 0..m {
                for j in 0..n {
                    want[at + layer.w_at + i * n + j] = (0..rows)
                        .map(|r| value(x, m, r, i) * value(dz, n, r, j))
                        .sum();
                }
            }
            if let Some(b) = layer.b_at {
                for j in 0..n {
                    want[at + b + j] = (0..rows).map(|r| value(dz, n, r, j)).sum();
                }
            }
        }
        // Past the span, each view's sums, then the canaries left.
        let [_, dz0] = &hosts[0];
        for g in 0..views {
            for j in 0..n0 {
                let of_view = (0..rows).filter(|&r| view_of(r) == g as u32);
                want.push(
                    of_view
                        .map(|r| f64::from(f16::from_bits(dz0[r * pad16(n0) + j])))
                        .sum(),
                );
            }
        }
        want.extend([-1.0; 7]);
        for (e, (&g, &w)) in got.iter().zip(&want).enumerate() {
            let g = f64::from(g);
            assert!(
                (g - w).abs() < 1e-4 * (1.0 + w.abs()),
                "value {e} is {g}, not {w}"
            );
        }
    }
}
