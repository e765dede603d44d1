//! The transport networks' share of a training step: each track's inputs (with its hash
//! grid's encoding), then its plan's networks in order with each view's light code folded into
//! the first bias of the step it enters, the loss and its gradient at the tracks' outputs, and backward
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
use nprt_gpu::{groups_for, Dispatch};

/// One track's state over a batch.
struct TrackTape {
    x: wgpu::Buffer,
    /// Gradient at `x`, for a track with a hash grid.
    dx: Option<wgpu::Buffer>,
    /// Each step's tape, in the order of the track's plan.
    steps: Vec<MlpTape>,
    /// Gradient at the last step's outputs.
    d_out: wgpu::Buffer,
}

impl TrackTape {
    /// The last step's outputs, which the combine reads.
    fn output(&self) -> &wgpu::Buffer {
        &self.steps.last().expect("a track has a step").output
    }
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
                    tape.output(),
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
                    tape.output(),
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
                    tape.output(),
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

    /// A track's forward pass over the batch: its plan's steps in order, the step the light
    /// enters with each view's light code folded into its first bias.
    fn track_forward(&self, plan: &mut Vec<Dispatch>, t: &TrackAt, b: &BatchBuffers) -> TrackTape {
        let gpu = &self.gpu;
        let x = gpu.buffer(b.rows * t.width);
        let (params, rows) = (&self.params, b.rows);
        plan.push(t.record_inputs(gpu, params, &self.resolutions, [&b.features, &x], rows));
        // The light code's share of the lit step's first layer, once per view.
        let group_bias = t.plan.lit().map(|step| {
            let bias = gpu.buffer(b.views * t.mlp(step.net).layers[0].d_out);
            plan.push(t.record_code_share(gpu, params, &b.codes, b.views, &bias));
            bias
        });
        let mut steps: Vec<MlpTape> = Vec::with_capacity(t.plan.steps.len());
        for step in &t.plan.steps {
            let m = t.mlp(step.net);
            let tape = MlpTape::new(gpu, m, rows);
            let bias = match (&step.code_rows, &group_bias) {
                (Some(_), Some(group)) => Bias::Group(group, &b.view),
                _ => Bias::Column(params, m.layers[0].bias.offset),
            };
            let first = FirstLayer {
                own_row: step.own_row,
                count: step.own_width,
                bias,
            };
            let input = Held::F32(steps.last().map_or(&x, |s| &s.output));
            let to = ForwardTargets::Tape(&tape);
            m.record_forward(gpu, plan, params, input, rows, first, &to);
            steps.push(tape);
        }
        TrackTape {
            dx: t.grid.map(|_| gpu.buffer(b.rows * t.width)),
            x,
            steps,
            d_out: gpu.buffer(b.rows * t.plan.last().outputs),
        }
    }

    /// A track's backward pass, from the gradient at its last step's outputs in `tape.d_out`,
    /// through its plan's steps in reverse.
    fn track_backward(
        &self,
        plan: &mut Vec<Dispatch>,
        t: &TrackAt,
        tape: &TrackTape,
        b: &BatchBuffers,
    ) {
        let gpu = &self.gpu;
        let steps = &t.plan.steps;
        // The gradient at each step's outputs but the last's (its next step's input).
        let d_between: Vec<wgpu::Buffer> = (steps.iter().skip(1))
            .map(|s| gpu.buffer(b.rows * s.own_width))
            .collect();
        // The code's rows of the lit step's first weight and the code's gradient, from each
        // view's sums of the gradient at that layer's pre-activation (which also make its
        // bias's).
        let d_views = gpu.buffer(b.views * t.mlp(t.plan.last().net).layers[0].d_out);
        let from_views = |plan: &mut Vec<Dispatch>| {
            let step = t.plan.lit().expect("only the lit step sums by view");
            let first = &t.mlp(step.net).layers[0];
            let code = step.code_rows.clone().expect("the lit step reads the code");
            let code_size = code.len();
            let code_weights = first.weight.offset + code.start * first.d_out;
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
        for (i, step) in steps.iter().enumerate().rev() {
            let input = match i {
                0 => &tape.x,
                _ => &tape.steps[i - 1].output,
            };
            let d_out = d_between.get(i).unwrap_or(&tape.d_out);
            // At the first step, the gradient at the inputs is needed only to train the grid.
            let d_input = match i {
                0 => tape.dx.as_ref(),
                _ => Some(&d_between[i - 1]),
            };
            self.trainable().mlp_backward(
                plan,
                t.mlp(step.net),
                &tape.steps[i],
                (input, step.own_row, step.own_width),
                d_out,
                d_input,
                step.code_rows.as_ref().map(|_| &view_sums),
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
