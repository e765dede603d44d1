//! The Deep Shading U-Net on the CPU engine: forward over a batch of whole views keeping what
//! backward needs, the masked log-L1 loss, and backward into parameter gradients, one view per
//! task on all cores, the views' gradients summed in order.

use rayon::prelude::*;

use super::accumulate;
use super::matmul::{matmul, MatRef, Op};
use super::pool::{max_pool, unpool};
use super::relu::{relu, relu_back};
use crate::encoding::features::FEATURES;
use crate::loss::Loss;
use crate::network::conv::Conv;
use crate::network::encoder::{LightInput, CODE_SIZE};
use crate::network::unet::{DeepShading, LEVELS};
use crate::parameters::Parameters;
use crate::shading::UnetShading;

/// Views of one padded size, channel-major planes each.
pub struct UnetBatch {
    /// views × [FEATURES, h, w].
    pub features: Vec<f32>,
    /// views × [3, h, w] reference radiance (zero on the background).
    pub radiance: Vec<f32>,
    /// views × [h, w]: 1 where the pixel counts.
    pub mask: Vec<f32>,
    /// views × [3, W/2, W] pre-processed maps.
    pub lights: Vec<f32>,
    pub light_width: usize,
    /// views × 3: what each map's channels were divided by.
    pub scale: Vec<f32>,
    pub height: usize,
    pub width: usize,
}

impl UnetBatch {
    fn views(&self) -> usize {
        self.scale.len() / 3
    }
}

/// What one view's forward pass keeps: every convolution's input and ReLU output, the pools'
/// sources, and the prediction.
struct ViewTape {
    /// Inputs of down[0..6], bottleneck[0..2], up[0..3], out.
    inputs: Vec<Vec<f32>>,
    /// ReLU outputs in the same order (none for `out`).
    relu: Vec<Vec<f32>>,
    argmax: Vec<Vec<u32>>,
    /// exp of the output, times the map's scale: [3, h, w].
    prediction: Vec<f32>,
}

/// Nearest-neighbour ×2 up-sampling of `x` (c × h × w).
fn upsample(x: &[f32], c: usize, (h, w): (usize, usize)) -> Vec<f32> {
    let mut out = vec![0.0; c * 4 * h * w];
    for (i, o) in out.iter_mut().enumerate() {
        let (ch, y, xo) = (i / (4 * h * w), i / (2 * w) % (2 * h), i % (2 * w));
        *o = x[(ch * h + y / 2) * w + xo / 2];
    }
    out
}

/// The adjoint of [`upsample`]: each 2×2 block's gradients summed (c × h × w out).
fn downsample_sum(d: &[f32], c: usize, (h, w): (usize, usize)) -> Vec<f32> {
    let mut out = vec![0.0; c * h * w];
    for (i, g) in d.iter().enumerate() {
        let (ch, y, xo) = (i / (4 * h * w), i / (2 * w) % (2 * h), i % (2 * w));
        out[(ch * h + y / 2) * w + xo / 2] += g;
    }
    out
}

impl DeepShading {
    /// The convolutions in the order a view's tape lists them.
    fn convs(&self) -> impl Iterator<Item = &Conv> {
        self.down
            .iter()
            .chain(&self.bottleneck)
            .chain(&self.up)
            .chain([&self.out])
    }

    /// The bottleneck offsets of each view (`views × WIDTHS[LEVELS]`) from its light code.
    fn offsets(&self, codes: &[f32]) -> Vec<f32> {
        let b = self.code.d_out;
        let mut out = vec![0.0; codes.len() / CODE_SIZE * b];
        let codes_m = MatRef::new(codes, codes.len() / CODE_SIZE, CODE_SIZE);
        let w = MatRef::new(&self.code.weight, CODE_SIZE, b);
        matmul(&mut out, b, false, codes_m, Op::Plain, w, Op::Plain);
        for row in out.chunks_exact_mut(b) {
            accumulate(row, &self.code.bias);
        }
        out
    }

    /// One view's forward pass: `features` (FEATURES × h × w), the bottleneck `offset` and the
    /// map's `scale`.
    fn view_forward(
        &self,
        features: &[f32],
        offset: &[f32],
        scale: &[f32],
        (h, w): (usize, usize),
    ) -> ViewTape {
        let mut tape = ViewTape {
            inputs: Vec::new(),
            relu: Vec::new(),
            argmax: Vec::new(),
            prediction: Vec::new(),
        };
        let mut cols = Vec::new();
        let mut x = features.to_vec();
        let mut size = (h, w);
        let mut conv = |tape: &mut ViewTape, layer: &Conv, x: Vec<f32>, size: (usize, usize)| {
            let mut y = layer.forward(&x, size.0, size.1, &mut cols);
            tape.inputs.push(x);
            if !std::ptr::eq(layer, &self.out) {
                relu(&mut y);
                tape.relu.push(y.clone());
            }
            y
        };
        let mut skips = Vec::new();
        for pair in self.down.chunks(2) {
            let a = conv(&mut tape, &pair[0], x, size);
            let b = conv(&mut tape, &pair[1], a, size);
            let (pooled, argmax) = max_pool(pair[1].c_out, size, |i| b[i]);
            tape.argmax.push(argmax);
            skips.push(b);
            x = pooled;
            size = (size.0 / 2, size.1 / 2);
        }
        // The offset is added after the first bottleneck convolution's ReLU.
        let mut a = conv(&mut tape, &self.bottleneck[0], x, size);
        for (plane, o) in a.chunks_exact_mut(size.0 * size.1).zip(offset) {
            plane.iter_mut().for_each(|v| *v += o);
        }
        x = conv(&mut tape, &self.bottleneck[1], a, size);
        for (up, skip) in self.up.iter().zip(skips.into_iter().rev()) {
            let mut input = upsample(&x, x.len() / (size.0 * size.1), size);
            size = (size.0 * 2, size.1 * 2);
            input.extend_from_slice(&skip);
            x = conv(&mut tape, up, input, size);
        }
        let mut y = conv(&mut tape, &self.out, x, size);
        for (plane, s) in y.chunks_exact_mut(h * w).zip(scale) {
            plane.iter_mut().for_each(|v| *v = v.exp() * s);
        }
        tape.prediction = y;
        tape
    }

    /// Gradients of one view's U-Net weights (the light encoder's left zero) and at its
    /// bottleneck offset, given the gradient `d_pred` at its prediction.
    fn view_backward(
        &self,
        tape: &ViewTape,
        mut d_pred: Vec<f32>,
        (h, w): (usize, usize),
    ) -> (DeepShading, Vec<f32>) {
        let mut g = self.zeros_like();
        // d exp(y)·s / dy = the prediction.
        d_pred
            .iter_mut()
            .zip(&tape.prediction)
            .for_each(|(d, p)| *d *= p);
        let convs: Vec<&Conv> = self.convs().collect();
        let last = convs.len() - 1;
        let mut grads: Vec<Conv> = convs.iter().map(|c| c.zeros_like()).collect();
        // Gradient at each convolution's input, computed from the output back.
        let step = |i: usize, d_out: &[f32], size: (usize, usize), grads: &mut Vec<Conv>| {
            let mut d_x = vec![0.0; tape.inputs[i].len()];
            let wants = i > 0;
            convs[i].backward(
                &tape.inputs[i],
                size,
                d_out,
                &mut grads[i],
                wants.then_some(d_x.as_mut_slice()),
            );
            d_x
        };
        let mut d = step(last, &d_pred, (h, w), &mut grads);
        let mut size = (h, w);
        // Decoder, last convolution first: up[u] joins the skip of level LEVELS − 1 − u, so
        // the skips' gradients come out level 0 first.
        let mut d_skips = Vec::new();
        for u in (0..LEVELS).rev() {
            let i = 2 * LEVELS + 2 + u;
            relu_back(&mut d, &tape.relu[i]);
            let d_in = step(i, &d, size, &mut grads);
            let skip_len = tape.relu[2 * (LEVELS - 1 - u) + 1].len();
            let (d_up, d_skip) = d_in.split_at(d_in.len() - skip_len);
            d_skips.push(d_skip.to_vec());
            size = (size.0 / 2, size.1 / 2);
            d = downsample_sum(d_up, d_up.len() / (4 * size.0 * size.1), size);
        }
        // Bottleneck: its second convolution, the offset, its first.
        let b = 2 * LEVELS;
        relu_back(&mut d, &tape.relu[b + 1]);
        d = step(b + 1, &d, size, &mut grads);
        let hw = size.0 * size.1;
        let d_offset: Vec<f32> = d
            .chunks_exact(hw)
            .map(|p| p.iter().map(|&v| v as f64).sum::<f64>() as f32)
            .collect();
        relu_back(&mut d, &tape.relu[b]);
        d = step(b, &d, size, &mut grads);
        // Encoder levels, deepest first; each gets its skip's gradient back.
        for l in (0..LEVELS).rev() {
            let full = (size.0 * 2, size.1 * 2);
            let mut d_b = unpool(&d, &tape.argmax[l], full.0 * full.1);
            accumulate(&mut d_b, &d_skips[l]);
            size = full;
            relu_back(&mut d_b, &tape.relu[2 * l + 1]);
            let mut d_a = step(2 * l + 1, &d_b, size, &mut grads);
            relu_back(&mut d_a, &tape.relu[2 * l]);
            d = step(2 * l, &d_a, size, &mut grads);
        }
        let mut grads = grads.into_iter();
        for c in g.down.iter_mut().chain(&mut g.bottleneck).chain(&mut g.up) {
            *c = grads.next().expect("a gradient per convolution");
        }
        g.out = grads.next().expect("the output convolution's gradient");
        (g, d_offset)
    }

    /// The batch's mean masked `loss` (over every foreground pixel's channels) and, when
    /// `train`, every parameter's gradient.
    pub fn loss_and_gradients(
        &self,
        batch: &UnetBatch,
        loss: Loss,
        train: bool,
    ) -> (f64, Option<DeepShading>) {
        let (h, w) = (batch.height, batch.width);
        let hw = h * w;
        let light = self.light.forward(&batch.lights, batch.light_width);
        let offsets = self.offsets(&light.codes);
        let b = self.code.d_out;
        let tapes: Vec<ViewTape> = (0..batch.views())
            .into_par_iter()
            .map(|v| {
                let f = &batch.features[v * FEATURES * hw..][..FEATURES * hw];
                let s = &batch.scale[3 * v..3 * v + 3];
                self.view_forward(f, &offsets[v * b..][..b], s, (h, w))
            })
            .collect();
        let foreground: f64 = batch.mask.iter().map(|&m| m as f64).sum();
        let norm = (3.0 * foreground).max(1.0);
        let mut total = 0.0f64;
        let mut d_preds = Vec::with_capacity(tapes.len());
        for (v, tape) in tapes.iter().enumerate() {
            let reference = &batch.radiance[v * 3 * hw..][..3 * hw];
            let mask = &batch.mask[v * hw..][..hw];
            let mut d = vec![0.0; 3 * hw];
            for (i, (&p, &r)) in tape.prediction.iter().zip(reference).enumerate() {
                let m = mask[i % hw];
                let (value, slope) = loss.element(p, r);
                total += (value * m) as f64;
                d[i] = slope * m / norm as f32;
            }
            d_preds.push(d);
        }
        if !train {
            return (total / norm, None);
        }
        let parts: Vec<(DeepShading, Vec<f32>)> = tapes
            .par_iter()
            .zip(d_preds)
            .map(|(tape, d)| self.view_backward(tape, d, (h, w)))
            .collect();
        let mut d_offsets = Vec::with_capacity(parts.len() * b);
        let mut g = self.zeros_like();
        for (part, d_offset) in &parts {
            g.add(part);
            d_offsets.extend_from_slice(d_offset);
        }
        // The code's dense layer, then the light encoder.
        let views = batch.views();
        let codes = MatRef::new(&light.codes, views, CODE_SIZE);
        let d_off = MatRef::new(&d_offsets, views, b);
        matmul(
            &mut g.code.weight,
            b,
            false,
            codes,
            Op::Transposed,
            d_off,
            Op::Plain,
        );
        for row in d_offsets.chunks_exact(b) {
            accumulate(&mut g.code.bias, row);
        }
        let mut d_codes = vec![0.0; views * CODE_SIZE];
        let w_code = MatRef::new(&self.code.weight, CODE_SIZE, b);
        matmul(
            &mut d_codes,
            CODE_SIZE,
            false,
            d_off,
            Op::Plain,
            w_code,
            Op::Transposed,
        );
        g.light = self.light.backward(&light, &d_codes);
        (total / norm, Some(g))
    }

    /// Radiance of one view (3 × h × w) for its `features` (FEATURES × h × w) and map.
    pub fn shade(
        &self,
        features: &[f32],
        light: &[f32],
        light_width: usize,
        scale: [f32; 3],
        (h, w): (usize, usize),
    ) -> Vec<f32> {
        let codes = self.light.forward(light, light_width).codes;
        let offsets = self.offsets(&codes);
        self.view_forward(features, &offsets, &scale, (h, w))
            .prediction
    }
}

impl UnetShading for DeepShading {
    fn radiance(&self, features: Vec<f32>, light: LightInput, size: (usize, usize)) -> Vec<f32> {
        self.shade(&features, &light.pixels, light.width, light.scale, size)
    }
}
