//! The Deep Shading U-Net. Widths are chosen for about the parameter count of the Neural PRT
//! designs (≈200 K without the encoder).

use burn::module::Module;
use burn::nn::conv::Conv2d;
use burn::nn::pool::{MaxPool2d, MaxPool2dConfig};
use burn::nn::Linear;
use burn::tensor::activation::relu;
use burn::tensor::Tensor;
use nprt_trace::GBuffer;

use crate::encoding::features::gbuffer_features;
use crate::encoding::features::FEATURES;
use crate::init::{conv2d, shifted_bias, Init};
use crate::network::activation::Activation;
use crate::network::encoder::{LightEncoder, CODE_SIZE};
use crate::network::mlp::Mlp;

/// Channels of the encoder levels (full, ½, ¼ resolution) and of the ⅛-resolution bottleneck.
const WIDTHS: [usize; 4] = [16, 32, 64, 64];

#[derive(Module, Debug)]
pub struct DeepShading {
    pub light: LightEncoder,
    /// Two 3×3 convolutions per encoder level.
    pub down: Vec<Conv2d>,
    pub bottleneck: Vec<Conv2d>,
    /// The light code as a per-channel offset of the bottleneck.
    pub code: Linear,
    /// One 3×3 convolution per decoder level, on [upsampled, skip].
    pub up: Vec<Conv2d>,
    pub out: Conv2d,
    pub pool: MaxPool2d,
}

fn upsample(x: Tensor<4>) -> Tensor<4> {
    let [b, c, h, w] = x.dims();
    x.reshape([b, c, h, 1, w, 1])
        .expand([b, c, h, 2, w, 2])
        .reshape([b, c, 2 * h, 2 * w])
}

impl DeepShading {
    pub fn new(init: &mut Init, encoder_width: usize) -> Self {
        let light = LightEncoder::new(init, encoder_width);
        let mut down = Vec::new();
        let mut c_in = FEATURES;
        for &w in &WIDTHS[..3] {
            down.push(conv2d(init, c_in, w, 3));
            down.push(conv2d(init, w, w, 3));
            c_in = w;
        }
        let b = WIDTHS[3];
        let bottleneck = vec![conv2d(init, WIDTHS[2], b, 3), conv2d(init, b, b, 3)];
        let code = Mlp::new(init, &[CODE_SIZE, b], Activation::Relu)
            .layers
            .remove(0);
        let up = vec![
            conv2d(init, b + WIDTHS[2], WIDTHS[1], 3),
            conv2d(init, WIDTHS[1] + WIDTHS[1], WIDTHS[0], 3),
            conv2d(init, WIDTHS[0] + WIDTHS[0], WIDTHS[0], 3),
        ];
        DeepShading {
            light,
            down,
            bottleneck,
            code,
            up,
            out: conv2d(init, WIDTHS[0], 3, 1),
            pool: MaxPool2dConfig::new([2, 2]).with_strides([2, 2]).init(),
        }
    }

    /// Parameters without the light encoder (comparable to the designs' transport counts).
    pub fn unet_params(&self) -> usize {
        self.num_params() - self.light.num_params()
    }

    /// Adds `log_level` to the output convolution's bias (see `NprtNet::shift_output_level`).
    pub fn shift_output_level(mut self, log_level: f32) -> Self {
        self.out.bias = shifted_bias(self.out.bias.take(), log_level);
        self
    }

    /// Radiance [B, 3, H, W] from G-buffer features [B, 19, H, W] (H, W multiples of 8),
    /// pre-processed maps [B, 3, W/2, W] and what each map's channels were divided by [B, 3].
    pub fn forward(&self, features: Tensor<4>, light: Tensor<4>, scale: Tensor<2>) -> Tensor<4> {
        let code = self.light.forward(light);
        let mut x = features;
        let mut skips = Vec::new();
        for pair in self.down.chunks(2) {
            x = relu(pair[1].forward(relu(pair[0].forward(x))));
            skips.push(x.clone());
            x = self.pool.forward(x);
        }
        x = relu(self.bottleneck[0].forward(x));
        let [b, c, h, w] = x.dims();
        x = x + self
            .code
            .forward(code)
            .reshape([b, c, 1, 1])
            .expand([b, c, h, w]);
        x = relu(self.bottleneck[1].forward(x));
        for (conv, skip) in self.up.iter().zip(skips.into_iter().rev()) {
            x = relu(conv.forward(Tensor::cat(vec![upsample(x), skip], 1)));
        }
        let [b, _, h, w] = x.dims();
        self.out.forward(x).exp() * scale.reshape([b, 3, 1, 1]).expand([b, 3, h, w])
    }
}

/// A view's G-buffer as a [19, H', W'] feature image, zero on the background and padded to
/// multiples of 8; returns the padded size too.
pub fn feature_image(
    bounds: &[[f32; 3]; 2],
    g: &GBuffer,
    width: usize,
    height: usize,
) -> (Vec<f32>, usize, usize) {
    let (pw, ph) = (width.div_ceil(8) * 8, height.div_ceil(8) * 8);
    let mut img = vec![0.0; FEATURES * pw * ph];
    for i in (0..g.mask.len()).filter(|&i| g.mask[i] > 0.5) {
        let f = gbuffer_features(bounds, g, i);
        let (x, y) = (i % width, i / width);
        for (k, v) in f.iter().enumerate() {
            img[k * pw * ph + y * pw + x] = *v;
        }
    }
    (img, pw, ph)
}
