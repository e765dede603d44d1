//! The network's forward pass recorded on the device, written once for its two callers: a
//! training step (over a batch, keeping what backward needs) and the frame path (over a
//! camera's pixels, through ping-pong activations). Both read the weights from one flat
//! parameter buffer where [`NetworkLayout`](crate::gpu::layers::network_layout::NetworkLayout) places them.

use crate::gpu::kernels::TRACK_INPUTS;
use crate::gpu::layers::mlp_tape::MlpTape;
use crate::gpu::layers::network_layout::{MlpAt, TrackAt};
use crate::gpu::products::codes::activation_code;
use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::half_layers::{half_train_layer, pad16, HalfLayers, HalfOut, Held};
use crate::gpu::products::half_mlp::{fits, half_mlp, FusedIo, FusedLayer, Pre};
use crate::gpu::products::operands::{Bias, Operand, Output};
use nprt_gpu::{groups_for, Bind, Dispatch, GpuDevice, Part};

/// How an MLP's first layer reads its input: from weight row `own_row`, `count` values per
/// row, with `bias` (the light code's share folded in, for a shading network).
pub struct FirstLayer<'a> {
    pub own_row: usize,
    pub count: usize,
    pub bias: Bias<'a>,
}

/// Where an MLP's forward pass writes.
pub enum ForwardTargets<'a> {
    /// A frame's: each layer's output (f32 rows, or in half precision the hidden layers' f16
    /// rows, which the next layer reads); `input16` takes an f32 input made f16 where a half
    /// precision pass runs a layer a dispatch.
    Frame {
        outputs: Vec<Held<'a>>,
        input16: Option<&'a wgpu::Buffer>,
    },
    /// A training step's: what backward reads too.
    Tape(&'a MlpTape),
}

impl ForwardTargets<'_> {
    /// Layer `i` of `last`'s output in an f32 pass: its buffer and first value.
    fn f32_output(&self, i: usize, last: usize) -> (&wgpu::Buffer, usize) {
        match self {
            ForwardTargets::Frame { outputs, .. } => match outputs[i] {
                Held::F32(b) => (b, 0),
                Held::F16(_) => unreachable!("f16 rows in an f32 pass"),
            },
            ForwardTargets::Tape(tape) if i == last => (&tape.output, 0),
            ForwardTargets::Tape(tape) => {
                let part = tape.hidden(i);
                (part.buffer, part.span.offset)
            }
        }
    }
}

impl MlpAt {
    /// Records this MLP over `rows` rows of `x` into `to`, its weights in `params`: in f32, or
    /// in half precision where its layers hold f16 copies ([`MlpAt::half`]).
    #[allow(clippy::too_many_arguments)]
    pub fn record_forward(
        &self,
        gpu: &GpuDevice,
        plan: &mut Vec<Dispatch>,
        params: &wgpu::Buffer,
        x: Held,
        rows: usize,
        first: FirstLayer,
        to: &ForwardTargets,
    ) {
        if !self.half.is_empty() {
            return match to {
                ForwardTargets::Tape(tape) => {
                    self.record_half_training(gpu, plan, params, x, rows, first, tape)
                }
                ForwardTargets::Frame { outputs, input16 } => {
                    let to = (outputs.as_slice(), *input16);
                    self.record_half_frame(gpu, plan, params, x, rows, first, to)
                }
            };
        }
        let Held::F32(x) = x else {
            unreachable!("f16 rows outside half precision");
        };
        let last = self.layers.len() - 1;
        let mut first = Some(first);
        for (i, layer) in self.layers.iter().enumerate() {
            let ((input, input_at), own_row, count, bias) = match first.take() {
                Some(f) => ((x, 0), f.own_row, f.count, f.bias),
                None => (
                    to.f32_output(i - 1, last),
                    0,
                    layer.d_in,
                    Bias::Column(params, layer.bias.offset),
                ),
            };
            let (output, output_at) = to.f32_output(i, last);
            let pre = match to {
                ForwardTargets::Tape(tape) if i < last => Some(tape.pre(i)),
                _ => None,
            };
            plan.push(gpu.product(
                [rows, layer.d_out, count],
                Operand::plain(input, input_at, count),
                Operand::plain(
                    params,
                    layer.weight.offset + own_row * layer.d_out,
                    layer.d_out,
                ),
                bias,
                self.activation_of(i, last),
                Output::to(output, output_at, layer.d_out),
                pre.as_ref().map(|p| p as &dyn Bind),
            ));
        }
    }

    /// [`Self::record_forward`] of a frame in half precision: in one dispatch where the fused
    /// pass holds the MLP (`half_mlp`), else `x` made f16 unless it is, then a layer a dispatch
    /// (`half_layer`, what `nprt export` ships), each from the f16 output of the one before,
    /// on the layers' f16 copies of their weights (the first layer's of its own rows).
    #[allow(clippy::too_many_arguments)]
    fn record_half_frame(
        &self,
        gpu: &GpuDevice,
        plan: &mut Vec<Dispatch>,
        params: &wgpu::Buffer,
        x: Held,
        rows: usize,
        first: FirstLayer,
        (outputs, input16): (&[Held], Option<&wgpu::Buffer>),
    ) {
        let last = self.layers.len() - 1;
        let layers = self.fused_layers(&[]);
        if fits(gpu, &layers) {
            let (y16, y32) = match outputs[last] {
                Held::F16(y) => (Some(y), None),
                Held::F32(y) => (None, Some(y)),
            };
            let io = FusedIo {
                rows,
                x,
                x_cols: first.count,
                bias0: first.bias,
                biases: Some(params),
                y16,
                out16: y16.is_some(),
                kept_input: None,
                y32,
                pre: None,
            };
            plan.push(half_mlp(gpu, &layers, &io));
            return;
        }
        let x16 = match x {
            Held::F16(x) => x,
            Held::F32(x) => {
                let input = input16.expect("room for the input in f16");
                plan.push(gpu.half_rows([rows, first.count, first.count], x, input));
                input
            }
        };
        let mut first_bias = Some(first.bias);
        for (i, (layer, copies)) in self.half_layers().enumerate() {
            let (input, bias) = match first_bias.take() {
                Some(bias) => (x16, bias),
                None => match outputs[i - 1] {
                    Held::F16(b) => (b, Bias::Column(params, layer.bias.offset)),
                    Held::F32(_) => unreachable!("a hidden layer's f32 rows in half precision"),
                },
            };
            let bias = frame_bias(bias, layer.d_out);
            let k_pad = pad16(copies.count);
            let activation = self.activation_of(i, last);
            let y = outputs[i];
            plan.push(gpu.half_layer(rows, input, k_pad, &copies.stored, 0, &bias, activation, y));
        }
    }

    /// [`Self::record_forward`] of a training step in half precision, keeping what backward
    /// reads in `tape`: in one dispatch where the fused pass holds the MLP, else `x` made f16
    /// and a layer a dispatch (`half_train_layer`).
    #[allow(clippy::too_many_arguments)]
    fn record_half_training(
        &self,
        gpu: &GpuDevice,
        plan: &mut Vec<Dispatch>,
        params: &wgpu::Buffer,
        x: Held,
        rows: usize,
        first: FirstLayer,
        tape: &MlpTape,
    ) {
        let Held::F32(x) = x else {
            unreachable!("a training step's input in f16");
        };
        let last = self.layers.len() - 1;
        if let Some(kept) = tape.kept() {
            let io = FusedIo {
                rows,
                x: Held::F32(x),
                x_cols: first.count,
                bias0: first.bias,
                biases: Some(params),
                y16: Some(kept.held),
                out16: false,
                kept_input: Some(kept.input_at),
                y32: Some(&tape.output),
                pre: Some((kept.pre, Pre::Keep)),
            };
            plan.push(half_mlp(gpu, &self.fused_layers(&kept.layers), &io));
            return;
        }
        let x16 = tape.input16().expect("a mixed-precision tape");
        plan.push(gpu.half_rows([rows, first.count, first.count], x, &x16));
        let mut first_bias = Some(first.bias);
        for (i, (layer, copies)) in self.half_layers().enumerate() {
            let hidden_in;
            let (input, bias): (&dyn Bind, _) = match first_bias.take() {
                Some(bias) => (&x16, bias),
                None => {
                    hidden_in = tape.hidden(i - 1);
                    (&hidden_in, Bias::Column(params, layer.bias.offset))
                }
            };
            let kept = (i < last).then(|| [tape.pre(i), tape.hidden(i)]);
            let out = match &kept {
                Some([z, y16]) => HalfOut {
                    z: Some(z),
                    y16: Some(y16),
                    y32: None,
                },
                None => HalfOut {
                    z: None,
                    y16: None,
                    y32: Some(&tape.output),
                },
            };
            let activation = self.activation_of(i, last);
            let k_pad = pad16(copies.count);
            let layer = half_train_layer(
                gpu,
                rows,
                (input, k_pad),
                &copies.stored,
                bias,
                activation,
                out,
            );
            plan.push(layer);
        }
    }

    /// Whether a fused pass on `gpu` holds this MLP (`half_mlp`).
    pub fn fuses(&self, gpu: &GpuDevice) -> bool {
        fits(gpu, &self.fused_layers(&[]))
    }

    /// This MLP's layers as a fused forward pass takes them, the hidden ones' places in a
    /// training tape from `kept` (`[f16 output, pre-activation]`; none for a frame).
    fn fused_layers(&self, kept: &[[usize; 2]]) -> Vec<FusedLayer<'_>> {
        let last = self.layers.len() - 1;
        (self.half_layers().enumerate())
            .map(|(i, (layer, copies))| {
                let [held_at, pre_at] = kept.get(i).copied().unwrap_or_default();
                FusedLayer {
                    weight: &copies.stored,
                    k_pad: pad16(copies.count),
                    bias_at: layer.bias.offset,
                    activation: self.activation_of(i, last),
                    held_at,
                    pre_at,
                }
            })
            .collect()
    }

    /// Layer `i`'s activation code: the MLP's for a hidden layer, linear for the last.
    fn activation_of(&self, i: usize, last: usize) -> u32 {
        match i == last {
            true => 0,
            false => activation_code(self.activation),
        }
    }
}

impl TrackAt {
    /// The dispatch that gathers this track's inputs for `rows` rows of `features` into `x`
    /// (its feature indices, then its hash grid's encoding from `params`).
    pub fn record_inputs(
        &self,
        gpu: &GpuDevice,
        params: &wgpu::Buffer,
        resolutions: &wgpu::Buffer,
        [features, x]: [&wgpu::Buffer; 2],
        rows: usize,
    ) -> Dispatch {
        let grid = self.grid.map(|span| Part {
            buffer: params,
            span,
        });
        let table: &dyn Bind = match &grid {
            Some(part) => part,
            None => &gpu.empty,
        };
        let words = [
            rows,
            self.count,
            self.width,
            usize::from(self.grid.is_some()),
        ];
        gpu.prepare(
            &TRACK_INPUTS,
            &words.map(|v| v as u32),
            &[features, &self.index, table, resolutions, x],
            groups_for(rows),
        )
    }

    /// The dispatch of the light code's share of the first layer of the step the light enters
    /// (its plan's): `codes` (`lights` rows of the code) times the layer's code rows, plus its
    /// bias, into `out` (a row per light), which that network then takes as its first bias.
    pub fn record_code_share(
        &self,
        gpu: &GpuDevice,
        params: &wgpu::Buffer,
        codes: &wgpu::Buffer,
        lights: usize,
        out: &wgpu::Buffer,
    ) -> Dispatch {
        let step = self.plan.lit().expect("a track whose network reads the light code");
        let first = &self.mlp(step.net).layers[0];
        let rows = step.code_rows.clone().expect("the lit step reads the code");
        let (code_row, code_size) = (rows.start, rows.len());
        gpu.product(
            [lights, first.d_out, code_size],
            Operand::plain(codes, 0, code_size),
            Operand::plain(
                params,
                first.weight.offset + code_row * first.d_out,
                first.d_out,
            ),
            Bias::Column(params, first.bias.offset),
            0,
            Output::to(out, 0, first.d_out),
            None,
        )
    }
}

/// A frame's bias of `len` values as one binding (a grouped bias is a training step's).
fn frame_bias(bias: Bias, len: usize) -> Part {
    let Bias::Column(buffer, offset) = bias else {
        unreachable!("a grouped bias outside training");
    };
    Part {
        buffer,
        span: nprt_gpu::Span { offset, len },
    }
}
