//! The network's forward pass recorded on the device, written once for its two callers: a
//! training step (over a batch, keeping what backward needs) and the frame path (over a
//! camera's pixels, through ping-pong activations). Both read the weights from one flat
//! parameter buffer where [`NetworkLayout`](crate::gpu::layers::network_layout::NetworkLayout) places them.

use crate::gpu::kernels::TRACK_INPUTS;
use crate::gpu::layers::network_layout::{MlpAt, TrackAt};
use crate::gpu::products::codes::activation_code;
use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::half_layers::{half_train_layer, pad16, HalfLayers, HalfOut, Held};
use crate::gpu::products::half_mlp::{fits, half_mlp, FusedLayer};
use crate::gpu::products::operands::{Bias, Operand, Output};
use crate::network::encoder::CODE_SIZE;
use nprt_gpu::{groups_for, Bind, Dispatch, GpuDevice, Part};

/// How an MLP's first layer reads its input: from weight row `own_row`, `count` values per
/// row, with `bias` (the light code's share folded in, for a shading network).
pub struct FirstLayer<'a> {
    pub own_row: usize,
    pub count: usize,
    pub bias: Bias<'a>,
}

/// Where an MLP's forward pass writes: each layer's output (f32 rows, or in half precision the
/// hidden layers' f16 rows, which the next layer reads), and for training each hidden layer's
/// pre-activation; in half precision, `input16` takes an f32 input made f16.
pub struct ForwardTargets<'a> {
    pub outputs: Vec<Held<'a>>,
    pub pre: Option<&'a [wgpu::Buffer]>,
    pub input16: Option<&'a wgpu::Buffer>,
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
            return self.record_half_forward(gpu, plan, params, x, rows, first, to);
        }
        let Held::F32(x) = x else {
            unreachable!("f16 rows outside half precision");
        };
        let last = self.layers.len() - 1;
        let mut first = Some(first);
        for (i, layer) in self.layers.iter().enumerate() {
            let (input, own_row, count, bias) = match first.take() {
                Some(f) => (x, f.own_row, f.count, f.bias),
                None => (
                    f32_rows(to.outputs[i - 1]),
                    0,
                    layer.d_in,
                    Bias::Column(params, layer.bias.offset),
                ),
            };
            plan.push(gpu.product(
                [rows, layer.d_out, count],
                Operand::plain(input, 0, count),
                Operand::plain(
                    params,
                    layer.weight.offset + own_row * layer.d_out,
                    layer.d_out,
                ),
                bias,
                self.activation_of(i, last),
                Output::to(f32_rows(to.outputs[i]), 0, layer.d_out),
                to.pre.and_then(|p| p.get(i)),
            ));
        }
    }

    /// [`Self::record_forward`] in half precision: `x` made f16 unless it is, then each layer's
    /// product from the f16 output of the one before, on the layers' f16 copies of their
    /// weights (the first layer's of its own rows). Training keeps the pre-activations
    /// (`half_train_layer`); frames keep nothing (`half_layer`, what `nprt export` ships).
    #[allow(clippy::too_many_arguments)]
    fn record_half_forward(
        &self,
        gpu: &GpuDevice,
        plan: &mut Vec<Dispatch>,
        params: &wgpu::Buffer,
        x: Held,
        rows: usize,
        first: FirstLayer,
        to: &ForwardTargets,
    ) {
        if to.pre.is_none() {
            if let Some(fused) = self.fused_forward(gpu, params, x, rows, &first, to) {
                plan.push(fused);
                return;
            }
        }
        let x16 = match x {
            Held::F16(x) => x,
            Held::F32(x) => {
                let input = to.input16.expect("room for the input in f16");
                plan.push(gpu.half_rows([rows, first.count, first.count], x, input));
                input
            }
        };
        let last = self.layers.len() - 1;
        let mut first_bias = Some(first.bias);
        for (i, (layer, copies)) in self.half_layers().enumerate() {
            let (input, bias) = match first_bias.take() {
                Some(bias) => (x16, bias),
                None => (
                    half_rows(to.outputs[i - 1]),
                    Bias::Column(params, layer.bias.offset),
                ),
            };
            let activation = self.activation_of(i, last);
            let k_pad = pad16(copies.count);
            plan.push(match to.pre {
                Some(pre) => {
                    let (y16, y32) = match to.outputs[i] {
                        Held::F16(y) => (Some(y), None),
                        Held::F32(y) => (None, Some(y)),
                    };
                    let out = HalfOut {
                        z: pre.get(i),
                        y16,
                        y32,
                    };
                    half_train_layer(
                        gpu,
                        rows,
                        (input, k_pad),
                        &copies.stored,
                        bias,
                        activation,
                        out,
                    )
                }
                None => {
                    let bias = frame_bias(bias, layer.d_out);
                    let y = to.outputs[i];
                    gpu.half_layer(rows, input, k_pad, &copies.stored, 0, &bias, activation, y)
                }
            });
        }
    }

    /// A frame's forward pass of this MLP in one dispatch (`half_mlp`), from `x` as it is held
    /// into the last of `to.outputs`; `None` where the fused pass cannot hold the MLP.
    fn fused_forward(
        &self,
        gpu: &GpuDevice,
        params: &wgpu::Buffer,
        x: Held,
        rows: usize,
        first: &FirstLayer,
        to: &ForwardTargets,
    ) -> Option<Dispatch> {
        let last = self.layers.len() - 1;
        let layers: Vec<FusedLayer> = (self.half_layers().enumerate())
            .map(|(i, (layer, copies))| FusedLayer {
                weight: &copies.stored,
                k_pad: pad16(copies.count),
                bias_at: layer.bias.offset,
                activation: self.activation_of(i, last),
            })
            .collect();
        if !fits(gpu, &layers) {
            return None;
        }
        let bias0 = frame_bias(first.bias, self.layers[0].d_out);
        let y = to.outputs[last];
        let x = (x, first.count);
        Some(half_mlp(gpu, rows, x, &layers, &bias0, params, y))
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

    /// The dispatch of the light code's share of the first shading layer: `codes` (`lights`
    /// rows of the code) times the layer's code rows, plus its bias, into `out` (a row per
    /// light), which the shading network then takes as its first bias.
    pub fn record_code_share(
        &self,
        gpu: &GpuDevice,
        params: &wgpu::Buffer,
        codes: &wgpu::Buffer,
        lights: usize,
        out: &wgpu::Buffer,
    ) -> Dispatch {
        let first = &self.shading.layers[0];
        let (code_row, _) = self.code_and_own_rows();
        gpu.product(
            [lights, first.d_out, CODE_SIZE],
            Operand::plain(codes, 0, CODE_SIZE),
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

fn f32_rows<'a>(held: Held<'a>) -> &'a wgpu::Buffer {
    match held {
        Held::F32(b) => b,
        Held::F16(_) => unreachable!("f16 rows in an f32 pass"),
    }
}

fn half_rows<'a>(held: Held<'a>) -> &'a wgpu::Buffer {
    match held {
        Held::F16(b) => b,
        Held::F32(_) => unreachable!("a hidden layer's f32 rows in a half-precision pass"),
    }
}
