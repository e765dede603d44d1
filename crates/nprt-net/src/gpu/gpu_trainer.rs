//! A design's training step on the GPU: the light encoder's and the transport networks'
//! forward passes keeping what backward needs, the loss and its gradient, backward into every
//! parameter's gradient, and one Adam step over all parameters, recorded as one queue
//! submission of our own kernels (a handful of dispatches per layer) with no host round trip
//! inside it.
//!
//! It computes what the CPU engine computes ([`HostEncoder`] and [`HostTransport`]), in f32,
//! and the tests hold the two together; Adam is burn's formulation, which the CPU path steps
//! with.

use std::sync::Arc;

use std::collections::HashMap;
use std::path::Path;

use anyhow::{anyhow, Context, Result};
use safetensors::{tensor::TensorView, Dtype, SafeTensors};

use super::kernels::{
    ACTIVATION_BACKWARD, ADAM, COLUMN_SUM, ENCODER_BLOCK, ENCODER_INPUT_BACKWARD,
    ENCODER_POOL_BACKWARD, ENCODER_WEIGHT_BACKWARD, GEMM, GEMM_TILE, GRID_BACKWARD, RADIANCE_LOSS,
    TRACK_INPUTS,
};
use super::parameters::{ParameterLayout, Span};
use super::{groups_for, Bind, GpuDevice, Part};
use crate::cpu::{DenseStack, HostEncoder, HostTransport, Samples};
use crate::encoding::hash_grid;
use crate::network::activation::Activation;
use crate::network::design::TRANSPORT_CODE;
use crate::network::encoder::{CHANNELS, CODE_SIZE};
use crate::network::nprt_net::NprtNet;
use crate::network::track::TrackKind;
use crate::training::loss::Loss;
use crate::training::training_loop::ADAM_EPSILON;

const BETA_1: f32 = 0.9;
/// Threads of `grid_backward`: one per 64 slots of each level's table.
const GRID_BACKWARD_THREADS: usize = hash_grid::LEVELS * hash_grid::TABLE_SIZE / 64;
const BETA_2: f32 = 0.999;

/// One dense layer's place in the flat buffers.
struct DenseAt {
    weight: Span,
    bias: Span,
    d_in: usize,
    d_out: usize,
}

struct MlpAt {
    layers: Vec<DenseAt>,
    activation: Activation,
}

/// One track's networks on the device.
struct TrackAt {
    kind: TrackKind,
    /// The feature indices the track reads, in its input order.
    index: wgpu::Buffer,
    count: usize,
    /// Inputs per row: `count` plus the hash grid's encoding.
    width: usize,
    grid: Option<Span>,
    transfer: Option<MlpAt>,
    shading: MlpAt,
}

impl TrackAt {
    /// The shading network's first weight row that multiplies the light code, and the first
    /// that multiplies the per-row input: [ŝ, ê] after a transfer network, [ê, inputs] for the
    /// baseline.
    fn code_and_own_rows(&self) -> (usize, usize) {
        match self.transfer {
            Some(_) => (TRANSPORT_CODE, 0),
            None => (0, CODE_SIZE),
        }
    }

    /// Width of the shading network's per-row input.
    fn own_width(&self) -> usize {
        match self.transfer {
            Some(_) => TRANSPORT_CODE,
            None => self.width,
        }
    }
}

/// One encoder block's convolution in the flat buffers.
struct ConvAt {
    weight: Span,
    bias: Span,
    c_in: usize,
}

/// A network's parameters, gradients and Adam moments on the device, and the step that trains
/// them.
pub struct GpuTrainer {
    gpu: Arc<GpuDevice>,
    layout: ParameterLayout,
    convs: Vec<ConvAt>,
    to_code: DenseAt,
    /// The network's shapes on the host (their values are the initial ones, not kept current).
    encoder: HostEncoder,
    transport: HostTransport,
    tracks: Vec<TrackAt>,
    params: wgpu::Buffer,
    grads: wgpu::Buffer,
    moment1: wgpu::Buffer,
    moment2: wgpu::Buffer,
    /// Adam steps taken.
    steps: u64,
    resolutions: wgpu::Buffer,
    /// Bound where a kernel's read-only input is unused, and where a written one is.
    empty: wgpu::Buffer,
    spare: wgpu::Buffer,
}

/// One operand of a product: element (i, k) at `offset + i · rows + k · cols` of `buffer`.
struct Operand<'a> {
    buffer: &'a wgpu::Buffer,
    offset: usize,
    rows: usize,
    cols: usize,
}

impl<'a> Operand<'a> {
    /// A row-major matrix with `stride` values per row, from `offset`.
    fn plain(buffer: &'a wgpu::Buffer, offset: usize, stride: usize) -> Self {
        Operand {
            buffer,
            offset,
            rows: stride,
            cols: 1,
        }
    }

    /// The transpose of a row-major matrix with `stride` values per row.
    fn transposed(buffer: &'a wgpu::Buffer, offset: usize, stride: usize) -> Self {
        Operand {
            buffer,
            offset,
            rows: 1,
            cols: stride,
        }
    }
}

/// What a product adds before its activation.
enum Bias<'a> {
    None,
    /// `d_out` values from an offset of a buffer.
    Column(&'a wgpu::Buffer, usize),
    /// One row of `d_out` values per group, and each row's group.
    Group(&'a wgpu::Buffer, &'a wgpu::Buffer),
}

/// A product's output: `rows` values apart from `offset` of `buffer`, written or added to.
struct Output<'a> {
    buffer: &'a wgpu::Buffer,
    offset: usize,
    stride: usize,
    accumulate: bool,
}

impl<'a> Output<'a> {
    fn to(buffer: &'a wgpu::Buffer, offset: usize, stride: usize) -> Self {
        Output {
            buffer,
            offset,
            stride,
            accumulate: false,
        }
    }
}

/// How an MLP's first layer reads its input: from weight row `own_row`, `count` values per
/// row, with `bias`.
struct FirstLayer<'a> {
    own_row: usize,
    count: usize,
    bias: Bias<'a>,
}

/// What takes a first layer's bias gradient, given the gradient at its pre-activation.
type FirstLayerBias<'a> = &'a dyn Fn(&mut wgpu::ComputePass, &wgpu::Buffer);

/// What an MLP's forward pass keeps: each layer's output and each hidden layer's
/// pre-activation.
struct MlpTape {
    outputs: Vec<wgpu::Buffer>,
    pre: Vec<wgpu::Buffer>,
}

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

/// What the encoder's forward pass keeps: each block's input, (h, w) and pooling tape, and
/// the last block's output (the flattened input of the code layer).
struct EncoderTape {
    inputs: Vec<wgpu::Buffer>,
    sizes: Vec<(usize, usize)>,
    tapes: Vec<wgpu::Buffer>,
    flat: wgpu::Buffer,
}

/// A batch on the device, and what its step computes besides gradients.
struct BatchBuffers {
    rows: usize,
    views: usize,
    light_width: usize,
    lights: wgpu::Buffer,
    features: wgpu::Buffer,
    radiance: wgpu::Buffer,
    scale: wgpu::Buffer,
    view: wgpu::Buffer,
    codes: wgpu::Buffer,
    d_codes: wgpu::Buffer,
    row_loss: wgpu::Buffer,
    loss: wgpu::Buffer,
}

fn activation_code(a: Activation) -> u32 {
    match a {
        Activation::Relu => 1,
        Activation::Siren => 2,
    }
}

fn kind_code(kind: TrackKind) -> u32 {
    match kind {
        TrackKind::Full => 0,
        TrackKind::Albedo => 1,
        TrackKind::Diffuse => 2,
        TrackKind::Specular => 3,
    }
}

fn loss_code(loss: Loss) -> u32 {
    match loss {
        Loss::LogL1 => 0,
        Loss::RelL2 => 1,
    }
}

/// The layers of `stack`, their spans taken in order from `spans`.
fn mlp_at(stack: &DenseStack, spans: &mut impl Iterator<Item = Span>) -> MlpAt {
    let mut take = || spans.next().expect("a span per tensor");
    MlpAt {
        layers: stack
            .layers
            .iter()
            .map(|l| DenseAt {
                weight: take(),
                bias: take(),
                d_in: l.d_in,
                d_out: l.d_out,
            })
            .collect(),
        activation: stack.activation,
    }
}

impl GpuTrainer {
    /// Uploads `net`'s parameters to the process's GPU device, with zero Adam moments.
    pub fn new(net: &NprtNet) -> Result<Self> {
        let gpu = GpuDevice::get()?;
        let encoder = HostEncoder::from_burn(&net.encoder);
        let transport = HostTransport::from_net(net);
        let align = gpu.device.limits().min_storage_buffer_offset_alignment as usize / 4;
        let (layout, flat) = ParameterLayout::pack(&encoder, &transport, align.max(1));
        // Spans in the order ParameterLayout walks the tensors: the encoder's, then the tracks'.
        let mut spans = layout.spans.iter().copied();
        let convs = encoder
            .convs
            .iter()
            .map(|c| ConvAt {
                weight: spans.next().expect("a span per tensor"),
                bias: spans.next().expect("a span per tensor"),
                c_in: c.c_in,
            })
            .collect();
        let to_code = DenseAt {
            weight: spans.next().expect("a span per tensor"),
            bias: spans.next().expect("a span per tensor"),
            d_in: encoder.to_code.d_in,
            d_out: encoder.to_code.d_out,
        };
        let tracks = transport
            .tracks
            .iter()
            .map(|t| {
                let index: Vec<u32> = t.kind.inputs().iter().map(|&i| i as u32).collect();
                let grid = t.grid.as_ref().map(|_| spans.next().expect("a grid span"));
                let transfer = t.transfer.as_ref().map(|s| mlp_at(s, &mut spans));
                TrackAt {
                    kind: t.kind,
                    index: gpu.upload(&index),
                    count: index.len(),
                    width: index.len() + grid.map_or(0, |_| hash_grid::OUTPUTS),
                    grid,
                    transfer,
                    shading: mlp_at(&t.shading, &mut spans),
                }
            })
            .collect();
        let zeros = vec![0.0f32; layout.total];
        Ok(GpuTrainer {
            params: gpu.upload(&flat),
            grads: gpu.upload(&zeros),
            moment1: gpu.upload(&zeros),
            moment2: gpu.upload(&zeros),
            steps: 0,
            resolutions: gpu.upload(&hash_grid::resolutions()),
            empty: gpu.upload(&[0u32; 4]),
            spare: gpu.buffer(4),
            tracks,
            convs,
            to_code,
            layout,
            encoder,
            transport,
            gpu,
        })
    }

    /// The device's adapter, for reports.
    pub fn adapter(&self) -> &str {
        &self.gpu.adapter
    }

    /// The parameters' current values, in the network's shapes.
    pub fn parameters(&self) -> (HostEncoder, HostTransport) {
        let flat = self.gpu.read(&self.params, self.layout.total);
        self.layout.unpack(&flat, &self.encoder, &self.transport)
    }

    /// The gradients of the last step, in the network's shapes.
    pub fn gradients(&self) -> (HostEncoder, HostTransport) {
        let flat = self.gpu.read(&self.grads, self.layout.total);
        self.layout.unpack(&flat, &self.encoder, &self.transport)
    }

    /// The loss of `batch` and every parameter's gradient, kept on the device
    /// ([`Self::gradients`] reads them): one submission of the encoder's and the transport
    /// networks' forward and backward passes. Reading the loss back waits for it.
    pub fn backward(&mut self, batch: &Samples, loss: Loss) -> f64 {
        let views = batch.lights.len() / (3 * batch.light_width * batch.light_width / 2);
        let b = self.upload_batch(batch, views);
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&self.grads, 0, None);
        encoder.clear_buffer(&b.d_codes, 0, None);
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            let tape = self.encoder_forward(&mut pass, &b);
            self.record_transport(&mut pass, &b, loss);
            self.encoder_backward(&mut pass, &b, &tape);
        }
        self.gpu.queue.submit([encoder.finish()]);
        let total = self.gpu.read(&b.loss, 1)[0] as f64;
        total / (3 * b.rows.max(1)) as f64
    }

    /// One training step: [`Self::backward`], then [`Self::adam`] at learning rate `lr`.
    pub fn step(&mut self, batch: &Samples, loss: Loss, lr: f64) -> f64 {
        let value = self.backward(batch, loss);
        self.adam(lr);
        value
    }

    /// One Adam step at learning rate `lr` over every parameter, from the gradients of the
    /// last step.
    pub fn adam(&mut self, lr: f64) {
        self.steps += 1;
        let t = self.steps as i32;
        let correction2 = (1.0 - BETA_2.powi(t)).sqrt();
        let factor = correction2 / (1.0 - BETA_1.powi(t));
        let mut params = vec![self.layout.total as u32, 0, 0, 0];
        params.extend(
            [
                lr as f32,
                BETA_1,
                BETA_2,
                factor,
                ADAM_EPSILON * correction2,
                0.0,
                0.0,
                0.0,
            ]
            .map(f32::to_bits),
        );
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.gpu.dispatch(
                &mut pass,
                &ADAM,
                &params,
                &[&self.grads, &self.params, &self.moment1, &self.moment2],
                groups_for(self.layout.total),
            );
        }
        self.gpu.queue.submit([encoder.finish()]);
    }

    /// Writes Adam's state (both moments, flat, and the step count) to `path` as safetensors.
    pub fn save_state(&self, path: &Path) -> Result<()> {
        let total = self.layout.total;
        let moments = [&self.moment1, &self.moment2].map(|m| self.gpu.read(m, total));
        let bytes = moments
            .each_ref()
            .map(|m| bytemuck::cast_slice::<f32, u8>(m));
        let views = ["moment1", "moment2"]
            .into_iter()
            .zip(bytes)
            .map(|(name, b)| Ok((name, TensorView::new(Dtype::F32, vec![total], b)?)))
            .collect::<Result<Vec<_>, safetensors::SafeTensorError>>()?;
        let metadata = HashMap::from([("steps".to_string(), self.steps.to_string())]);
        let file = safetensors::serialize(views, Some(metadata))?;
        nprt_io::write_file(path, &file)
    }

    /// Reads Adam's state back from `path` (written by [`Self::save_state`] for a network of
    /// the same shapes).
    pub fn load_state(&mut self, path: &Path) -> Result<()> {
        let bytes = std::fs::read(path)
            .with_context(|| format!("cannot read Adam's state '{}'", path.display()))?;
        let bad = |why: String| anyhow!("Adam's state '{}' {why}", path.display());
        let file =
            SafeTensors::deserialize(&bytes).map_err(|e| bad(format!("is unreadable: {e}")))?;
        let (_, metadata) = SafeTensors::read_metadata(&bytes).map_err(|e| bad(e.to_string()))?;
        let steps = metadata
            .metadata()
            .as_ref()
            .and_then(|m| m.get("steps"))
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| bad("has no step count".into()))?;
        for (name, buffer) in [("moment1", &self.moment1), ("moment2", &self.moment2)] {
            let view = file
                .tensor(name)
                .map_err(|e| bad(format!("lacks {name}: {e}")))?;
            if view.dtype() != Dtype::F32 || view.shape() != [self.layout.total] {
                return Err(bad(format!(
                    "holds {name} of {:?} {:?}, not this network's {} f32",
                    view.dtype(),
                    view.shape(),
                    self.layout.total
                )));
            }
            let values: Vec<f32> = view
                .data()
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect();
            self.gpu.write(buffer, &values);
        }
        self.steps = steps;
        Ok(())
    }

    fn upload_batch(&self, batch: &Samples, views: usize) -> BatchBuffers {
        let gpu = &self.gpu;
        let view: Vec<u32> = batch.view.iter().map(|&v| v as u32).collect();
        BatchBuffers {
            rows: batch.len(),
            views,
            light_width: batch.light_width,
            lights: gpu.upload(batch.lights),
            features: gpu.upload(batch.features),
            radiance: gpu.upload(batch.radiance),
            scale: gpu.upload(batch.scale),
            view: gpu.upload(&view),
            codes: gpu.buffer(views * CODE_SIZE),
            d_codes: gpu.buffer(views * CODE_SIZE),
            row_loss: gpu.buffer(batch.len()),
            loss: gpu.buffer(1),
        }
    }

    /// Records the transport networks' forward pass, loss and backward over batch `b` lit by
    /// its `codes`: parameter gradients into `grads` (the grids' added to, so cleared before),
    /// the codes' gradient added to `d_codes`, the loss summed into `loss`.
    fn record_transport(&self, pass: &mut wgpu::ComputePass, b: &BatchBuffers, loss: Loss) {
        let tapes: Vec<TrackTape> = self
            .tracks
            .iter()
            .map(|t| self.track_forward(pass, t, b))
            .collect();
        let kinds: Vec<u32> = self.tracks.iter().map(|t| kind_code(t.kind)).collect();
        let last = tapes.last().expect("a track");
        let mut params = vec![
            b.rows as u32,
            kinds.len() as u32,
            kinds[0],
            *kinds.last().expect("a track"),
            loss_code(loss),
            0,
            0,
            0,
        ];
        params.extend([1.0 / (3 * b.rows.max(1)) as f32, 0.0, 0.0, 0.0].map(f32::to_bits));
        self.gpu.dispatch(
            pass,
            &RADIANCE_LOSS,
            &params,
            &[
                &b.features,
                &b.radiance,
                &b.scale,
                tapes[0].shading.outputs.last().expect("a layer"),
                last.shading.outputs.last().expect("a layer"),
                &tapes[0].d_out,
                &last.d_out,
                &b.row_loss,
            ],
            groups_for(b.rows),
        );
        self.column_sum(
            pass,
            &b.row_loss,
            b.rows,
            1,
            None,
            Output::to(&b.loss, 0, 1),
        );
        for (t, tape) in self.tracks.iter().zip(&tapes) {
            self.track_backward(pass, t, tape, b);
        }
    }

    /// Records the light encoder over the batch's maps: their codes into `b.codes`.
    fn encoder_forward(&self, pass: &mut wgpu::ComputePass, b: &BatchBuffers) -> EncoderTape {
        let gpu = &self.gpu;
        let (mut h, mut w) = (b.light_width / 2, b.light_width);
        let mut x = b.lights.clone();
        let mut tape = EncoderTape {
            inputs: Vec::new(),
            sizes: Vec::new(),
            tapes: Vec::new(),
            flat: x.clone(),
        };
        for conv in &self.convs {
            let count = b.views * CHANNELS * (h / 2) * (w / 2);
            let (out, taken) = (gpu.buffer(count), gpu.buffer(count));
            let params = [conv.c_in, h, w, b.views, 1, 0, 0, 0].map(|v| v as u32);
            gpu.dispatch(
                pass,
                &ENCODER_BLOCK,
                &params,
                &[
                    &x,
                    &self.part(conv.weight),
                    &self.part(conv.bias),
                    &out,
                    &taken,
                ],
                groups_for(count),
            );
            tape.inputs.push(std::mem::replace(&mut x, out));
            tape.sizes.push((h, w));
            tape.tapes.push(taken);
            (h, w) = (h / 2, w / 2);
        }
        let flat = self.to_code.d_in;
        self.gemm(
            pass,
            [b.views, CODE_SIZE, flat],
            Operand::plain(&x, 0, flat),
            Operand::plain(&self.params, self.to_code.weight.offset, CODE_SIZE),
            Bias::Column(&self.params, self.to_code.bias.offset),
            0,
            Output::to(&b.codes, 0, CODE_SIZE),
            None,
        );
        tape.flat = x;
        tape
    }

    /// Records the light encoder's backward pass from the gradient at the codes, `b.d_codes`.
    fn encoder_backward(&self, pass: &mut wgpu::ComputePass, b: &BatchBuffers, tape: &EncoderTape) {
        let gpu = &self.gpu;
        let flat = self.to_code.d_in;
        self.gemm(
            pass,
            [flat, CODE_SIZE, b.views],
            Operand::transposed(&tape.flat, 0, flat),
            Operand::plain(&b.d_codes, 0, CODE_SIZE),
            Bias::None,
            0,
            Output::to(&self.grads, self.to_code.weight.offset, CODE_SIZE),
            None,
        );
        self.column_sum(
            pass,
            &b.d_codes,
            b.views,
            CODE_SIZE,
            None,
            Output::to(&self.grads, self.to_code.bias.offset, CODE_SIZE),
        );
        let mut d = gpu.buffer(b.views * flat);
        self.gemm(
            pass,
            [b.views, flat, CODE_SIZE],
            Operand::plain(&b.d_codes, 0, CODE_SIZE),
            Operand::transposed(&self.params, self.to_code.weight.offset, CODE_SIZE),
            Bias::None,
            0,
            Output::to(&d, 0, flat),
            None,
        );
        for (k, conv) in self.convs.iter().enumerate().rev() {
            let (h, w) = tape.sizes[k];
            let count = b.views * CHANNELS * h * w;
            let dz = gpu.buffer(count);
            // The gradient at the block's input; block 0's input is the map, which needs none.
            let d_input = match k {
                0 => self.spare.clone(),
                _ => gpu.buffer(b.views * conv.c_in * h * w),
            };
            let params = [conv.c_in, h, w, b.views, usize::from(k > 0), 0, 0, 0];
            gpu.dispatch(
                pass,
                &ENCODER_POOL_BACKWARD,
                &params.map(|v| v as u32),
                &[&tape.tapes[k], &d, &dz, &d_input],
                groups_for(count),
            );
            let params = [
                conv.c_in,
                h,
                w,
                b.views,
                conv.weight.offset,
                conv.bias.offset,
                0,
                0,
            ];
            gpu.dispatch(
                pass,
                &ENCODER_WEIGHT_BACKWARD,
                &params.map(|v| v as u32),
                &[&tape.inputs[k], &dz, &self.grads],
                groups_for(CHANNELS * (conv.c_in * 9 + 1)),
            );
            if k > 0 {
                let params = [conv.c_in, h, w, b.views, conv.weight.offset, 0, 0, 0];
                gpu.dispatch(
                    pass,
                    &ENCODER_INPUT_BACKWARD,
                    &params.map(|v| v as u32),
                    &[&self.params, &dz, &d_input],
                    groups_for(b.views * conv.c_in * h * w),
                );
            }
            d = d_input;
        }
    }

    /// One tensor of the parameters, bound on its own.
    fn part(&self, span: Span) -> Part<'_> {
        Part {
            buffer: &self.params,
            span,
        }
    }

    /// A track's forward pass over the batch.
    fn track_forward(
        &self,
        pass: &mut wgpu::ComputePass,
        t: &TrackAt,
        b: &BatchBuffers,
    ) -> TrackTape {
        let gpu = &self.gpu;
        let x = gpu.buffer(b.rows * t.width);
        let grid = t.grid.map(|span| self.part(span));
        let table: &dyn Bind = match &grid {
            Some(part) => part,
            None => &self.empty,
        };
        let params = [b.rows, t.count, t.width, usize::from(t.grid.is_some())].map(|v| v as u32);
        gpu.dispatch(
            pass,
            &TRACK_INPUTS,
            &params,
            &[&b.features, &t.index, table, &self.resolutions, &x],
            groups_for(b.rows),
        );
        let transfer = t.transfer.as_ref().map(|m| {
            let tape = self.tape(m, b.rows);
            let first = FirstLayer {
                own_row: 0,
                count: t.width,
                bias: Bias::Column(&self.params, m.layers[0].bias.offset),
            };
            self.mlp_forward(pass, m, &x, b.rows, first, &tape);
            tape
        });
        // The light code's share of the first shading layer, once per view.
        let first = &t.shading.layers[0];
        let (code_row, own_row) = t.code_and_own_rows();
        let group_bias = gpu.buffer(b.views * first.d_out);
        self.gemm(
            pass,
            [b.views, first.d_out, CODE_SIZE],
            Operand::plain(&b.codes, 0, CODE_SIZE),
            Operand::plain(
                &self.params,
                first.weight.offset + code_row * first.d_out,
                first.d_out,
            ),
            Bias::Column(&self.params, first.bias.offset),
            0,
            Output::to(&group_bias, 0, first.d_out),
            None,
        );
        let shading = self.tape(&t.shading, b.rows);
        let input = transfer
            .as_ref()
            .map_or(&x, |tape| tape.outputs.last().expect("a layer"));
        let first_layer = FirstLayer {
            own_row,
            count: t.own_width(),
            bias: Bias::Group(&group_bias, &b.view),
        };
        self.mlp_forward(pass, &t.shading, input, b.rows, first_layer, &shading);
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
        pass: &mut wgpu::ComputePass,
        t: &TrackAt,
        tape: &TrackTape,
        b: &BatchBuffers,
    ) {
        let gpu = &self.gpu;
        let first = &t.shading.layers[0];
        let (code_row, own_row) = t.code_and_own_rows();
        let code_weights = first.weight.offset + code_row * first.d_out;
        // The shading network's input gradient: at ŝ, or at the baseline's inputs (needed only
        // to train its grid).
        let d_s = t
            .transfer
            .as_ref()
            .map(|_| gpu.buffer(b.rows * TRANSPORT_CODE));
        let d_input = d_s.as_ref().or(tape.dx.as_ref());
        let input = tape
            .transfer
            .as_ref()
            .map_or(&tape.x, |tr| tr.outputs.last().expect("a layer"));
        // Each view's sum of the first layer's pre-activation gradients: its bias's, its code
        // rows' and the code's gradients all follow from it.
        let d_views = gpu.buffer(b.views * first.d_out);
        let on_first = |pass: &mut wgpu::ComputePass, dz: &wgpu::Buffer| {
            self.column_sum(
                pass,
                dz,
                b.rows,
                first.d_out,
                Some((&b.view, b.views)),
                Output::to(&d_views, 0, first.d_out),
            );
            self.column_sum(
                pass,
                &d_views,
                b.views,
                first.d_out,
                None,
                Output::to(&self.grads, first.bias.offset, first.d_out),
            );
            self.gemm(
                pass,
                [CODE_SIZE, first.d_out, b.views],
                Operand::transposed(&b.codes, 0, CODE_SIZE),
                Operand::plain(&d_views, 0, first.d_out),
                Bias::None,
                0,
                Output::to(&self.grads, code_weights, first.d_out),
                None,
            );
            self.gemm(
                pass,
                [b.views, CODE_SIZE, first.d_out],
                Operand::plain(&d_views, 0, first.d_out),
                Operand::transposed(&self.params, code_weights, first.d_out),
                Bias::None,
                0,
                Output {
                    accumulate: true,
                    ..Output::to(&b.d_codes, 0, CODE_SIZE)
                },
                None,
            );
        };
        self.mlp_backward(
            pass,
            &t.shading,
            &tape.shading,
            (input, own_row, t.own_width()),
            &tape.d_out,
            d_input,
            Some(&on_first),
        );
        if let (Some(m), Some(tr), Some(d_s)) = (&t.transfer, &tape.transfer, &d_s) {
            self.mlp_backward(
                pass,
                m,
                tr,
                (&tape.x, 0, t.width),
                d_s,
                tape.dx.as_ref(),
                None,
            );
        }
        if let (Some(span), Some(dx)) = (t.grid, &tape.dx) {
            let d_table = Part {
                buffer: &self.grads,
                span,
            };
            let params = [b.rows, t.count, t.width, 0].map(|v| v as u32);
            gpu.dispatch(
                pass,
                &GRID_BACKWARD,
                &params,
                &[&b.features, &self.resolutions, dx, &d_table],
                groups_for(GRID_BACKWARD_THREADS),
            );
        }
    }

    /// Buffers for an MLP's forward pass over `rows` rows.
    fn tape(&self, m: &MlpAt, rows: usize) -> MlpTape {
        let hidden = m.layers.len() - 1;
        MlpTape {
            outputs: m
                .layers
                .iter()
                .map(|l| self.gpu.buffer(rows * l.d_out))
                .collect(),
            pre: m.layers[..hidden]
                .iter()
                .map(|l| self.gpu.buffer(rows * l.d_out))
                .collect(),
        }
    }

    /// Records `m` over `rows` rows of `x`, keeping each layer's output and each hidden
    /// layer's pre-activation in `tape`.
    fn mlp_forward(
        &self,
        pass: &mut wgpu::ComputePass,
        m: &MlpAt,
        x: &wgpu::Buffer,
        rows: usize,
        first: FirstLayer,
        tape: &MlpTape,
    ) {
        let last = m.layers.len() - 1;
        let mut first = Some(first);
        for (i, layer) in m.layers.iter().enumerate() {
            let (input, own_row, count, bias) = match first.take() {
                Some(f) => (x, f.own_row, f.count, f.bias),
                None => (
                    &tape.outputs[i - 1],
                    0,
                    layer.d_in,
                    Bias::Column(&self.params, layer.bias.offset),
                ),
            };
            let activation = if i == last {
                0
            } else {
                activation_code(m.activation)
            };
            self.gemm(
                pass,
                [rows, layer.d_out, count],
                Operand::plain(input, 0, count),
                Operand::plain(
                    &self.params,
                    layer.weight.offset + own_row * layer.d_out,
                    layer.d_out,
                ),
                bias,
                activation,
                Output::to(&tape.outputs[i], 0, layer.d_out),
                tape.pre.get(i),
            );
        }
    }

    /// Records the backward pass of `m` from the gradient `d_last` at its output: every
    /// layer's weight and bias gradient into `grads`, and the gradient at its input into
    /// `d_input` where given. `input` is what the first layer read: the buffer, its first
    /// weight row and its values per row. `on_first`, where given, takes the first layer's
    /// bias gradient (it also receives the light code's share), given the gradient at that
    /// layer's pre-activation.
    #[allow(clippy::too_many_arguments)]
    fn mlp_backward(
        &self,
        pass: &mut wgpu::ComputePass,
        m: &MlpAt,
        tape: &MlpTape,
        input: (&wgpu::Buffer, usize, usize),
        d_last: &wgpu::Buffer,
        d_input: Option<&wgpu::Buffer>,
        on_first: Option<FirstLayerBias>,
    ) {
        let rows = tape.outputs[0].size() as usize / 4 / m.layers[0].d_out;
        let widest = m
            .layers
            .iter()
            .map(|l| l.d_in.max(l.d_out))
            .max()
            .unwrap_or(0);
        let scratch = [0, 1].map(|_| self.gpu.buffer(rows * widest));
        let last = m.layers.len() - 1;
        for (i, layer) in m.layers.iter().enumerate().rev() {
            let dz = if i == last { d_last } else { &scratch[i % 2] };
            if i < last {
                let count = rows * layer.d_out;
                let params = [count as u32, activation_code(m.activation), 0, 0];
                self.gpu.dispatch(
                    pass,
                    &ACTIVATION_BACKWARD,
                    &params,
                    &[&tape.pre[i], dz],
                    groups_for(count),
                );
            }
            let (x, own_row, count) = match i {
                0 => input,
                _ => (&tape.outputs[i - 1], 0, layer.d_in),
            };
            let weights = layer.weight.offset + own_row * layer.d_out;
            self.gemm(
                pass,
                [count, layer.d_out, rows],
                Operand::transposed(x, 0, count),
                Operand::plain(dz, 0, layer.d_out),
                Bias::None,
                0,
                Output::to(&self.grads, weights, layer.d_out),
                None,
            );
            match (i, on_first) {
                (0, Some(f)) => f(pass, dz),
                _ => self.column_sum(
                    pass,
                    dz,
                    rows,
                    layer.d_out,
                    None,
                    Output::to(&self.grads, layer.bias.offset, layer.d_out),
                ),
            }
            let dx = match i {
                0 => match d_input {
                    Some(d) => d,
                    None => continue,
                },
                _ => &scratch[(i - 1) % 2],
            };
            self.gemm(
                pass,
                [rows, count, layer.d_out],
                Operand::plain(dz, 0, layer.d_out),
                Operand::transposed(&self.params, weights, layer.d_out),
                Bias::None,
                0,
                Output::to(dx, 0, count),
                None,
            );
        }
    }

    /// Records C = A·B for `[m, n, k]` (C m × n), with `bias` and `activation` (0 linear,
    /// 1 ReLU, 2 SIREN) after, the pre-activation kept in `z` where given.
    #[allow(clippy::too_many_arguments)]
    fn gemm(
        &self,
        pass: &mut wgpu::ComputePass,
        [m, n, k]: [usize; 3],
        a: Operand,
        b: Operand,
        bias: Bias,
        activation: u32,
        c: Output,
        z: Option<&wgpu::Buffer>,
    ) {
        let (bias_mode, bias_buffer, bias_off, groups): (usize, &wgpu::Buffer, usize, _) =
            match bias {
                Bias::None => (0, &self.empty, 0, &self.empty),
                Bias::Column(buffer, offset) => (1, buffer, offset, &self.empty),
                Bias::Group(buffer, group) => (2, buffer, 0, group),
            };
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
            usize::from(z.is_some()),
            bias_off,
            c.offset,
        ];
        let tiles = |v: usize| (v as u32).div_ceil(GEMM_TILE);
        self.gpu.dispatch(
            pass,
            &GEMM,
            &params.map(|v| v as u32),
            &[
                a.buffer,
                b.buffer,
                bias_buffer,
                groups,
                c.buffer,
                z.unwrap_or(&self.spare),
            ],
            [tiles(n), tiles(m)],
        );
    }

    /// Records the sums over `rows` rows of the `n` columns of `x`, per group where `groups`
    /// gives each row's group and their number, into `out`.
    fn column_sum(
        &self,
        pass: &mut wgpu::ComputePass,
        x: &wgpu::Buffer,
        rows: usize,
        n: usize,
        groups: Option<(&wgpu::Buffer, usize)>,
        out: Output,
    ) {
        let (group_of, count) = groups.unwrap_or((&self.empty, 1));
        let params = [
            rows,
            n,
            count,
            usize::from(out.accumulate),
            out.offset,
            0,
            0,
            0,
        ];
        self.gpu.dispatch(
            pass,
            &COLUMN_SUM,
            &params.map(|v| v as u32),
            &[x, group_of, out.buffer],
            groups_for(count * n),
        );
    }
}
