//! The transport networks' share of a training step: each track's inputs (with its hash
//! grid's encoding), transfer and shading networks with each view's light code folded into the
//! first shading layer's bias, the loss and its gradient at the tracks' outputs, and backward
//! into every parameter, the grids' tables and the light codes.

use crate::gpu::kernels::{COMBINE, RADIANCE_LOSS, TRACK_GRADIENT, TRANSFER_LOSS};
use crate::gpu::layers::light_basis::{BasisAt, BasisFunctions};
use crate::gpu::layers::mlp_tape::MlpTape;
use crate::gpu::layers::network_forward::{FirstLayer, ForwardTargets};
use crate::gpu::layers::network_layout::{LightAt, TrackAt};
use crate::gpu::passes::grid_backward::{record_grid_backward, GridRows};
use crate::gpu::passes::mlp_step::ViewSums;
use crate::gpu::products::codes::loss_code;
use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::half_layers::Held;
use crate::gpu::products::operands::{Bias, Operand, Output};
use crate::gpu::trainers::gpu_trainer::{BatchBuffers, GpuTrainer, TransferBuffers};
use crate::loss::Loss;
use crate::network::design::TRANSPORT_CODE;
use nprt_gpu::{groups_for, Dispatch};

/// One track's state over a batch.
struct TrackTape {
    x: wgpu::Buffer,
    /// Gradient at `x`, for a track with a hash grid.
    dx: Option<wgpu::Buffer>,
    transfer: Option<MlpTape>,
    shading: MlpTape,
    /// Gradient at the shading network's outputs.
    d_out: wgpu::Buffer,
}

impl GpuTrainer {
    /// Records the transport networks' forward pass, loss and backward over batch `b` lit by
    /// its `codes`: parameter gradients into `grads`, the codes' gradient added to `d_codes`
    /// (cleared before), the loss summed into `loss`. Returns how many of `plan`'s dispatches
    /// it holds once the loss is made (the forward part).
    pub(crate) fn record_transport(
        &self,
        plan: &mut Vec<Dispatch>,
        b: &BatchBuffers,
        loss: Loss,
    ) -> usize {
        let tapes: Vec<TrackTape> = self
            .net
            .tracks
            .iter()
            .map(|t| self.track_forward(plan, t, b))
            .collect();
        match &b.transfer {
            Some(transfer) => self.record_transfer_loss(plan, b, transfer, &tapes),
            None => self.record_radiance_loss(plan, b, loss, &tapes),
        }
        self.gpu.column_sum(
            plan,
            &b.row_loss,
            b.rows,
            1,
            None,
            Output::to(&b.loss, 0, 1),
        );
        let forward = plan.len();
        self.record_gradients(plan, b, &tapes);
        forward
    }

    /// Each row's loss on `b`'s radiance and its gradient there: the tracks' radiance summed
    /// into `radiance_sum`, one track per dispatch (any number of tracks), then the loss and
    /// its gradient at that sum. A linear track reads its row's view's code.
    fn record_radiance_loss(
        &self,
        plan: &mut Vec<Dispatch>,
        b: &BatchBuffers,
        loss: Loss,
        tapes: &[TrackTape],
    ) {
        let code_size = self.net.light.code_size();
        for (k, (t, tape)) in self.net.tracks.iter().zip(tapes).enumerate() {
            let params = [
                b.rows,
                t.kind.code() as usize,
                usize::from(k > 0),
                0,
                0,
                0,
                t.light.coefficients(),
                code_size,
            ];
            plan.push(self.gpu.prepare(
                &COMBINE,
                &params.map(|v| v as u32),
                &[
                    &b.features,
                    &tape.shading.output,
                    &b.codes,
                    &b.view,
                    &b.radiance_sum,
                ],
                groups_for(b.rows),
            ));
        }
        let mut params = vec![b.rows as u32, loss_code(loss), 0, 0];
        let norm = b.grad_scale / (3 * b.rows.max(1)) as f32;
        params.extend([norm, 0.0, 0.0, 0.0].map(f32::to_bits));
        plan.push(self.gpu.prepare(
            &RADIANCE_LOSS,
            &params,
            &[
                &b.radiance_sum,
                &b.radiance,
                &b.scale,
                &b.d_radiance,
                &b.row_loss,
            ],
            groups_for(b.rows),
        ));
    }

    /// Each row's loss on `b`'s transfer vectors and its gradient there, one track per
    /// dispatch (transfer_loss.wgsl).
    fn record_transfer_loss(
        &self,
        plan: &mut Vec<Dispatch>,
        b: &BatchBuffers,
        transfer: &TransferBuffers,
        tapes: &[TrackTape],
    ) {
        let k = transfer.coefficients;
        let tracks = self.net.tracks.len();
        for (i, (t, tape)) in self.net.tracks.iter().zip(tapes).enumerate() {
            let mut params = vec![
                b.rows as u32,
                t.kind.code(),
                k as u32,
                u32::from(i > 0),
                u32::from(i + 1 == tracks),
                0,
                0,
            ];
            params.push((b.grad_scale / (3 * k * b.rows.max(1)) as f32).to_bits());
            plan.push(self.gpu.prepare(
                &TRANSFER_LOSS,
                &params,
                &[
                    &b.features,
                    &tape.shading.output,
                    &transfer.target,
                    &transfer.sum,
                    &transfer.d_transfer,
                    &b.row_loss,
                ],
                groups_for(b.rows),
            ));
        }
    }

    /// Backward from the gradient at the radiance in `b`: each track's gradient at its outputs
    /// (and, for a learned basis, at its rows' codes, summed per view into `d_codes`), then
    /// through its networks.
    fn record_gradients(&self, plan: &mut Vec<Dispatch>, b: &BatchBuffers, tapes: &[TrackTape]) {
        let code_size = self.net.light.code_size();
        // A learned basis needs the gradient at each view's code: per row, then per view.
        let learned = matches!(
            &self.net.light,
            LightAt::Basis(BasisAt {
                functions: BasisFunctions::Learned(_),
                ..
            })
        );
        let d_row_codes = learned.then(|| self.gpu.buffer(b.rows * code_size));
        for (t, tape) in self.net.tracks.iter().zip(tapes) {
            let d_rows = d_row_codes.as_ref().filter(|_| t.light.after_networks());
            let params = [
                b.rows,
                t.kind.code() as usize,
                t.light.coefficients(),
                code_size,
                usize::from(d_rows.is_some()),
                usize::from(b.transfer.is_some()),
                0,
                0,
            ];
            plan.push(self.gpu.prepare(
                &TRACK_GRADIENT,
                &params.map(|v| v as u32),
                &[
                    &b.features,
                    &tape.shading.output,
                    &b.codes,
                    &b.view,
                    b.transfer.as_ref().map_or(&b.d_radiance, |t| &t.d_transfer),
                    &tape.d_out,
                    d_rows.unwrap_or(&self.gpu.empty),
                ],
                groups_for(b.rows),
            ));
            if let Some(d_rows) = d_rows {
                let to = Output {
                    accumulate: true,
                    ..Output::to(&b.d_codes, 0, code_size)
                };
                let views = Some((&b.view, b.views));
                self.gpu
                    .column_sum(plan, d_rows, b.rows, code_size, views, to);
            }
            self.track_backward(plan, t, tape, b);
        }
    }

    /// A track's forward pass over the batch.
    fn track_forward(&self, plan: &mut Vec<Dispatch>, t: &TrackAt, b: &BatchBuffers) -> TrackTape {
        let gpu = &self.gpu;
        let x = gpu.buffer(b.rows * t.width);
        let (params, rows) = (&self.params, b.rows);
        plan.push(t.record_inputs(gpu, params, &self.resolutions, [&b.features, &x], rows));
        let transfer = t.transfer.as_ref().map(|m| {
            let tape = MlpTape::new(&self.gpu, m, rows);
            let first = FirstLayer {
                own_row: 0,
                count: t.width,
                bias: Bias::Column(params, m.layers[0].bias.offset),
            };
            let to = ForwardTargets::Tape(&tape);
            m.record_forward(gpu, plan, params, Held::F32(&x), rows, first, &to);
            tape
        });
        // The light code's share of the first shading layer, once per view (a linear track's
        // shading network reads ŝ alone).
        let first = &t.shading.layers[0];
        let group_bias;
        let bias = match t.light.code_rows() {
            Some(_) => {
                group_bias = gpu.buffer(b.views * first.d_out);
                plan.push(t.record_code_share(gpu, params, &b.codes, b.views, &group_bias));
                Bias::Group(&group_bias, &b.view)
            }
            None => Bias::Column(params, first.bias.offset),
        };
        let shading = MlpTape::new(&self.gpu, &t.shading, rows);
        let input = transfer.as_ref().map_or(&x, |tape| &tape.output);
        let first_layer = FirstLayer {
            own_row: t.light.own_row(),
            count: t.own_width(),
            bias,
        };
        let to = ForwardTargets::Tape(&shading);
        let input = Held::F32(input);
        (t.shading).record_forward(gpu, plan, params, input, rows, first_layer, &to);
        TrackTape {
            dx: t.grid.map(|_| gpu.buffer(b.rows * t.width)),
            x,
            transfer,
            d_out: gpu.buffer(b.rows * t.shading.layers.last().expect("a layer").d_out),
            shading,
        }
    }

    /// A track's backward pass, from the gradient at its shading outputs in `tape.d_out`.
    fn track_backward(
        &self,
        plan: &mut Vec<Dispatch>,
        t: &TrackAt,
        tape: &TrackTape,
        b: &BatchBuffers,
    ) {
        let gpu = &self.gpu;
        let first = &t.shading.layers[0];
        let own_row = t.light.own_row();
        let code_row = t.light.code_rows().map_or(0, |rows| rows.start);
        let code_size = t.light.code_inputs();
        let code_weights = first.weight.offset + code_row * first.d_out;
        // The shading network's input gradient: at ŝ, or at the baseline's inputs (needed only
        // to train its grid).
        let d_s = t
            .transfer
            .as_ref()
            .map(|_| gpu.buffer(b.rows * TRANSPORT_CODE));
        let d_input = d_s.as_ref().or(tape.dx.as_ref());
        let input = tape.transfer.as_ref().map_or(&tape.x, |tr| &tr.output);
        // The code's rows of the first shading weight and the code's gradient, from each
        // view's sums of the gradient at that layer's pre-activation (which also make its
        // bias's). A linear track's first layer has a bias of its own instead.
        let d_views = gpu.buffer(b.views * first.d_out);
        let from_views = |plan: &mut Vec<Dispatch>| {
            plan.push(self.gpu.product(
                [code_size, first.d_out, b.views],
                Operand::transposed(&b.codes, 0, code_size),
                Operand::plain(&d_views, 0, first.d_out),
                Bias::None,
                0,
                Output::to(&self.grads, code_weights, first.d_out),
                None,
            ));
            plan.push(self.gpu.product(
                [b.views, code_size, first.d_out],
                Operand::plain(&d_views, 0, first.d_out),
                Operand::transposed(&self.params, code_weights, first.d_out),
                Bias::None,
                0,
                Output {
                    accumulate: true,
                    ..Output::to(&b.d_codes, 0, code_size)
                },
                None,
            ));
        };
        let view_sums = ViewSums {
            view: &b.view,
            views: b.views,
            d_views: &d_views,
            then: &from_views,
        };
        self.trainable().mlp_backward(
            plan,
            &t.shading,
            &tape.shading,
            (input, own_row, t.own_width()),
            &tape.d_out,
            d_input,
            t.light.code_rows().map(|_| &view_sums),
        );
        if let (Some(m), Some(tr), Some(d_s)) = (&t.transfer, &tape.transfer, &d_s) {
            self.trainable().mlp_backward(
                plan,
                m,
                tr,
                (&tape.x, 0, t.width),
                d_s,
                tape.dx.as_ref(),
                None,
            );
        }
        self.grid_backward(plan, t, tape, b);
    }

    /// A hash grid's table gradient from the gradient at the track's inputs.
    fn grid_backward(
        &self,
        plan: &mut Vec<Dispatch>,
        t: &TrackAt,
        tape: &TrackTape,
        b: &BatchBuffers,
    ) {
        let (Some(span), Some(dx)) = (t.grid, &tape.dx) else {
            return;
        };
        let at = GridRows {
            features: &b.features,
            rows: b.rows,
            count: t.count,
            width: t.width,
        };
        let buffers = [&self.resolutions, dx, &self.grads];
        record_grid_backward(&self.gpu, plan, at, buffers, span);
    }
}
