//! The frame path's dense layers: an MLP's weights on the device (in f16 too where the
//! networks run in half precision) and the dispatches of its forward pass over rows of inputs,
//! through ping-pong activations.

use nprt_gpu::Dispatch;
use nprt_gpu::GpuDevice;
use nprt_net::gpu::{
    activation_code, pad16, Bias, DenseProducts, HalfLayers, HalfWeight, Held, Operand, Output,
};
use nprt_net::network::dense::Dense;
use nprt_net::network::mlp::Mlp;
use nprt_net::Activation;

/// One dense layer's weights (`d_in × d_out`, as the model file stores them) and bias on the device, and the
/// weights in f16 where the networks run in half precision.
pub(super) struct GpuDense {
    pub weight: wgpu::Buffer,
    pub bias: wgpu::Buffer,
    pub d_in: usize,
    pub d_out: usize,
    pub half: Option<HalfWeight>,
}

impl GpuDense {
    /// `d`'s weight and bias uploaded (f32 only).
    pub fn upload(gpu: &GpuDevice, d: &Dense) -> Self {
        GpuDense {
            weight: gpu.upload(&d.weight),
            bias: gpu.upload(&d.bias),
            d_in: d.d_in,
            d_out: d.d_out,
            half: None,
        }
    }
}

/// An MLP on the device: hidden layers take `activation`, the last is linear.
pub(super) struct GpuMlp {
    pub layers: Vec<GpuDense>,
    pub activation: Activation,
}

/// Ping-pong activations an MLP's layers run through: f32 and, where the networks run in half
/// precision, f16 (rows padded to a multiple of 256 and columns to 16).
pub(super) struct Scratch {
    pub f32: [wgpu::Buffer; 2],
    pub f16: Option<[wgpu::Buffer; 2]>,
}

/// How an MLP's first layer reads its input: the inputs per row (the row stride), the weight
/// row they start at, and a bias in place of the layer's own (the light code's share folded
/// in).
pub(super) struct FirstLayer<'a> {
    pub x_stride: usize,
    pub w_row: usize,
    pub bias: Option<&'a wgpu::Buffer>,
}

impl GpuMlp {
    /// `s`'s layers uploaded (f32 only).
    pub fn upload(gpu: &GpuDevice, s: &Mlp) -> Self {
        GpuMlp {
            layers: s.layers.iter().map(|d| GpuDense::upload(gpu, d)).collect(),
            activation: s.activation,
        }
    }

    /// The dispatches of this MLP over `rows` rows of `x` into `out`, through `scratch`,
    /// added to `list`: in half precision where `scratch` has f16 buffers (then `out` may be
    /// f16, and `x` is made f16 first where it is not), else in f32.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        gpu: &GpuDevice,
        list: &mut Vec<Dispatch>,
        x: Held,
        rows: usize,
        first: FirstLayer,
        scratch: &Scratch,
        out: Held,
    ) {
        if let Some(half) = &scratch.f16 {
            return self.record_half(gpu, list, x, rows, first, half, out);
        }
        let (Held::F32(x), Held::F32(out)) = (x, out) else {
            unreachable!("f16 rows outside half precision");
        };
        let scratch = &scratch.f32;
        let last = self.layers.len() - 1;
        for (i, layer) in self.layers.iter().enumerate() {
            let activation = if i == last {
                0
            } else {
                activation_code(self.activation)
            };
            let output = if i == last {
                out
            } else {
                &scratch[(i + 1) % 2]
            };
            let (input, d_in, w_row, bias) = match i {
                0 => (
                    x,
                    first.x_stride,
                    first.w_row,
                    first.bias.unwrap_or(&layer.bias),
                ),
                _ => (&scratch[i % 2], layer.d_in, 0, &layer.bias),
            };
            let layer_in = Rows {
                x: input,
                rows,
                d_in,
                w_row,
            };
            list.push(dense_layer(gpu, layer, layer_in, bias, activation, output));
        }
    }

    /// [`Self::record`] in half precision: `x` made f16 unless it is, then every layer f16 to
    /// f16 but the last, which writes `out`.
    #[allow(clippy::too_many_arguments)]
    fn record_half(
        &self,
        gpu: &GpuDevice,
        list: &mut Vec<Dispatch>,
        x: Held,
        rows: usize,
        first: FirstLayer,
        scratch: &[wgpu::Buffer; 2],
        out: Held,
    ) {
        let x = match x {
            Held::F16(x) => x,
            Held::F32(x) => {
                let stride = first.x_stride;
                list.push(gpu.half_rows([rows, stride, stride], x, &scratch[0]));
                &scratch[0]
            }
        };
        let last = self.layers.len() - 1;
        let mut k_pad = pad16(first.x_stride);
        for (i, layer) in self.layers.iter().enumerate() {
            let weight = layer.half.as_ref().expect("half-precision weights");
            let (activation, y) = if i == last {
                (0, out)
            } else {
                (
                    activation_code(self.activation),
                    Held::F16(&scratch[(i + 1) % 2]),
                )
            };
            let (input, w_row, bias) = match i {
                0 => (x, first.w_row, first.bias.unwrap_or(&layer.bias)),
                _ => (&scratch[i % 2], 0, &layer.bias),
            };
            list.push(gpu.half_layer(rows, input, k_pad, weight, w_row, bias, activation, y));
            k_pad = weight.n_pad;
        }
    }
}

/// The rows a dense layer reads: `rows × d_in` values of `x`, multiplied by the weight rows
/// from `w_row`.
pub(super) struct Rows<'a> {
    pub x: &'a wgpu::Buffer,
    pub rows: usize,
    pub d_in: usize,
    pub w_row: usize,
}

/// One dense layer's dispatch: `y = act(x·W[w_row..] + bias)`.
pub(super) fn dense_layer(
    gpu: &GpuDevice,
    layer: &GpuDense,
    x: Rows,
    bias: &wgpu::Buffer,
    activation: u32,
    y: &wgpu::Buffer,
) -> Dispatch {
    gpu.product(
        [x.rows, layer.d_out, x.d_in],
        Operand::plain(x.x, 0, x.d_in),
        Operand::plain(&layer.weight, x.w_row * layer.d_out, layer.d_out),
        Bias::Column(bias, 0),
        activation,
        Output::to(y, 0, layer.d_out),
        None,
    )
}
