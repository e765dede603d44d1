//! The light encoder on the CPU engine: forward over a batch's maps keeping what backward
//! needs, and backward into parameter gradients, one view per task on all cores. Each 3×3
//! convolution is one matrix product (`cpu::conv`), followed by one pass for ReLU and skip and
//! one for the 2×2 max-pool. burn's convolutions had taken about 30% of a training step
//! (`nprt bench train --views 1` against `--views 8`, docs/model.md).

use rayon::prelude::*;

use super::matmul::{matmul, MatRef, Op};
use super::pool::{max_pool, unpool};
use super::relu::{relu, relu_back};
use crate::network::encoder::{LightEncoder, CHANNELS, CODE_SIZE};
use crate::parameters::Parameters;

/// What one view's forward pass keeps for backward.
pub struct ViewTape {
    /// Each block's input, c_in × h × w, and its (h, w).
    inputs: Vec<Vec<f32>>,
    sizes: Vec<(usize, usize)>,
    /// Each block's ReLU output, CHANNELS × h × w: the gradient passes where it is positive.
    relu: Vec<Vec<f32>>,
    /// Each block's pooled outputs' sources: for every output value, its index in h × w.
    argmax: Vec<Vec<u32>>,
    /// The last block's output, flattened channel-major.
    flat: Vec<f32>,
}

/// A batch's light codes, `views × CODE_SIZE`, and what backward needs.
pub struct EncoderPass {
    pub codes: Vec<f32>,
    tapes: Vec<ViewTape>,
}

impl LightEncoder {
    /// The codes of `lights` (views × [3, W/2, W], channel-major, as a training `Batch`
    /// keeps them) for a map width `width`.
    pub fn forward(&self, lights: &[f32], width: usize) -> EncoderPass {
        let per_view = 3 * width * width / 2;
        let tapes: Vec<ViewTape> = lights
            .par_chunks(per_view)
            .map(|map| self.view_forward(map, width))
            .collect();
        let mut codes = vec![0.0; tapes.len() * CODE_SIZE];
        for (code, tape) in codes.chunks_exact_mut(CODE_SIZE).zip(&tapes) {
            let flat = MatRef::new(&tape.flat, 1, tape.flat.len());
            let w = MatRef::new(&self.to_code.weight, tape.flat.len(), CODE_SIZE);
            matmul(code, CODE_SIZE, false, flat, Op::Plain, w, Op::Plain);
            code.iter_mut()
                .zip(&self.to_code.bias)
                .for_each(|(c, b)| *c += b);
        }
        EncoderPass { codes, tapes }
    }

    fn view_forward(&self, map: &[f32], width: usize) -> ViewTape {
        let (mut h, mut w) = (width / 2, width);
        let mut x = map.to_vec();
        let mut tape = ViewTape {
            inputs: Vec::new(),
            sizes: Vec::new(),
            relu: Vec::new(),
            argmax: Vec::new(),
            flat: Vec::new(),
        };
        let mut cols = Vec::new();
        for conv in &self.convs {
            let hw = h * w;
            // z becomes the ReLU output.
            let mut z = conv.forward(&x, h, w, &mut cols);
            relu(&mut z);
            // The pool takes the ReLU output plus the skip (the input, zero-padded to CHANNELS
            // channels).
            let (pooled, argmax) = max_pool(CHANNELS, (h, w), |at| {
                if at < conv.c_in * hw {
                    z[at] + x[at]
                } else {
                    z[at]
                }
            });
            tape.inputs.push(std::mem::replace(&mut x, pooled));
            tape.sizes.push((h, w));
            tape.relu.push(z);
            tape.argmax.push(argmax);
            (h, w) = (h / 2, w / 2);
        }
        tape.flat = x;
        tape
    }

    /// Gradients of every weight, given the gradient at each view's code (`views × CODE_SIZE`),
    /// summed over the views in order so that the result does not depend on the threads.
    pub fn backward(&self, pass: &EncoderPass, d_codes: &[f32]) -> LightEncoder {
        pass.tapes
            .par_iter()
            .zip(d_codes.par_chunks(CODE_SIZE))
            .map(|(tape, d_code)| self.view_backward(tape, d_code))
            .collect::<Vec<_>>()
            .into_iter()
            .reduce(|mut a, b| {
                a.add(&b);
                a
            })
            .unwrap_or_else(|| self.zeros_like())
    }

    fn view_backward(&self, tape: &ViewTape, d_code: &[f32]) -> LightEncoder {
        let mut g = self.zeros_like();
        let flat = tape.flat.len();
        let d_code_m = MatRef::new(d_code, 1, CODE_SIZE);
        let flat_m = MatRef::new(&tape.flat, 1, flat);
        matmul(
            &mut g.to_code.weight,
            CODE_SIZE,
            false,
            flat_m,
            Op::Transposed,
            d_code_m,
            Op::Plain,
        );
        g.to_code.bias.copy_from_slice(d_code);
        let mut d_out = vec![0.0; flat];
        let w_code = MatRef::new(&self.to_code.weight, flat, CODE_SIZE);
        matmul(
            &mut d_out,
            flat,
            false,
            d_code_m,
            Op::Plain,
            w_code,
            Op::Transposed,
        );
        for (b, conv) in self.convs.iter().enumerate().rev() {
            let x = &tape.inputs[b];
            let (h, w) = tape.sizes[b];
            let hw = h * w;
            // Through the pool: each output's gradient to the value it took.
            let mut d_sum = unpool(&d_out, &tape.argmax[b], hw);
            // The skip passes the gradient to the input as it is; block 0's input is the map.
            let mut d_x = if b > 0 {
                d_sum[..conv.c_in * hw].to_vec()
            } else {
                Vec::new()
            };
            // Through the ReLU, then the convolution.
            relu_back(&mut d_sum, &tape.relu[b]);
            let d_input = (b > 0).then_some(d_x.as_mut_slice());
            conv.backward(x, (h, w), &d_sum, &mut g.convs[b], d_input);
            d_out = d_x;
        }
        g
    }
}
