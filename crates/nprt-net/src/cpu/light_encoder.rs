//! The light encoder on the host: forward over a batch's maps keeping what backward needs, and
//! backward into parameter gradients, one view per task on all cores. Each 3×3 convolution is
//! one matrix product over the map unfolded into its 3×3 neighbourhoods (im2col), followed by
//! one pass for bias, ReLU and skip and one for the 2×2 max-pool. burn's convolutions took about
//! 30% of a training step (`nprt bench train --views 1` against `--views 8`, docs/model.md).
//!
//! Computes what [`crate::network::encoder::LightEncoder::forward`] computes, in f32; the test that holds
//! the CPU engine to burn's autodiff covers every weight here.

use burn::nn::conv::Conv2d;
use rayon::prelude::*;

use super::accumulate;
use super::dense::{host, store, Dense};
use super::matmul::{matmul, MatRef, Op};
use crate::network::encoder::{LightEncoder, CHANNELS, CODE_SIZE};

/// Taps of a 3×3 kernel.
const TAPS: usize = 9;

/// One 3×3 convolution with "same" zero padding: `weight` is burn's [CHANNELS, c_in, 3, 3],
/// read as a row-major CHANNELS × (c_in · 9) matrix.
#[derive(Clone)]
pub struct Conv {
    pub weight: Vec<f32>,
    pub bias: Vec<f32>,
    pub c_in: usize,
}

/// The encoder's weights on the host, or (same shapes) their gradients.
#[derive(Clone)]
pub struct HostEncoder {
    pub convs: Vec<Conv>,
    pub to_code: Dense,
}

/// What one view's forward pass keeps for backward.
pub struct ViewTape {
    /// Each block's input, c_in × h × w, and its (h, w).
    inputs: Vec<Vec<f32>>,
    sizes: Vec<(usize, usize)>,
    /// Each block's ReLU output, CHANNELS × h × w: the gradient passes where it is positive.
    relu: Vec<Vec<f32>>,
    /// Each block's pooled outputs' sources: for every output value, its index in h × w.
    argmax: Vec<Vec<u32>>,
    /// The last block's output, flattened as burn's `flatten(1, 3)`.
    flat: Vec<f32>,
}

/// A batch's light codes, `views × CODE_SIZE`, and what backward needs.
pub struct EncoderPass {
    pub codes: Vec<f32>,
    tapes: Vec<ViewTape>,
}

impl Conv {
    fn from_burn(conv: &Conv2d) -> Self {
        let [c_out, c_in, kh, kw] = conv.weight.val().dims();
        assert_eq!((c_out, kh * kw), (CHANNELS, TAPS), "a 3×3 convolution");
        Conv {
            weight: host(&conv.weight),
            bias: conv.bias.as_ref().map_or(vec![0.0; c_out], host),
            c_in,
        }
    }

    /// Writes these values into `conv` (same shapes): the inverse of [`Self::from_burn`].
    fn store_into(&self, conv: &mut Conv2d) {
        store(&mut conv.weight, &self.weight);
        if let Some(b) = &mut conv.bias {
            store(b, &self.bias);
        }
    }

    fn zeros_like(&self) -> Self {
        Conv {
            weight: vec![0.0; self.weight.len()],
            bias: vec![0.0; self.bias.len()],
            c_in: self.c_in,
        }
    }

    fn matrix(&self) -> MatRef<'_> {
        MatRef::new(&self.weight, CHANNELS, self.c_in * TAPS)
    }
}

/// The source column of output column `x` under horizontal tap `kx`, if inside the map.
fn source(x: usize, kx: usize, w: usize) -> Option<usize> {
    (x + kx).checked_sub(1).filter(|&s| s < w)
}

/// The 3×3 neighbourhoods of `x` (c_in × h × w) as the rows of a (c_in · 9) × (h · w) matrix,
/// zero outside the map: row c · 9 + ky · 3 + kx holds x[c][y + ky − 1][x + kx − 1].
fn unfold(x: &[f32], c_in: usize, h: usize, w: usize, cols: &mut Vec<f32>) {
    cols.clear();
    cols.resize(c_in * TAPS * h * w, 0.0);
    for (row, dst) in cols.chunks_exact_mut(h * w).enumerate() {
        let (c, ky, kx) = (row / TAPS, row % TAPS / 3, row % 3);
        for y in 0..h {
            let Some(sy) = source(y, ky, h) else { continue };
            let src = &x[(c * h + sy) * w..][..w];
            let out = &mut dst[y * w..][..w];
            match kx {
                0 => out[1..].copy_from_slice(&src[..w - 1]),
                1 => out.copy_from_slice(src),
                _ => out[..w - 1].copy_from_slice(&src[1..]),
            }
        }
    }
}

/// The adjoint of [`unfold`]: adds each row's values back where they were read from.
fn fold_add(cols: &[f32], h: usize, w: usize, dx: &mut [f32]) {
    for (row, src) in cols.chunks_exact(h * w).enumerate() {
        let (c, ky, kx) = (row / TAPS, row % TAPS / 3, row % 3);
        for y in 0..h {
            let Some(sy) = source(y, ky, h) else { continue };
            let dst = &mut dx[(c * h + sy) * w..][..w];
            let grad = &src[y * w..][..w];
            let (to, from) = match kx {
                0 => (&mut dst[..w - 1], &grad[1..]),
                1 => (&mut dst[..], grad),
                _ => (&mut dst[1..], &grad[..w - 1]),
            };
            accumulate(to, from);
        }
    }
}

impl HostEncoder {
    pub fn from_burn(encoder: &LightEncoder) -> Self {
        HostEncoder {
            convs: encoder.convs.iter().map(Conv::from_burn).collect(),
            to_code: Dense::from_linear(&encoder.to_code),
        }
    }

    /// Writes these values into `encoder` (same shapes): the inverse of [`Self::from_burn`].
    pub fn store_into(&self, encoder: &mut LightEncoder) {
        for (c, conv) in self.convs.iter().zip(&mut encoder.convs) {
            c.store_into(conv);
        }
        self.to_code.store_into(&mut encoder.to_code);
    }

    fn zeros_like(&self) -> Self {
        HostEncoder {
            convs: self.convs.iter().map(Conv::zeros_like).collect(),
            to_code: self.to_code.zeros_like(),
        }
    }

    fn add(&mut self, other: &Self) {
        for (a, b) in self.convs.iter_mut().zip(&other.convs) {
            accumulate(&mut a.weight, &b.weight);
            accumulate(&mut a.bias, &b.bias);
        }
        self.to_code.add(&other.to_code);
    }

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
            unfold(&x, conv.c_in, h, w, &mut cols);
            let mut z = vec![0.0; CHANNELS * hw];
            let cols_m = MatRef::new(&cols, conv.c_in * TAPS, hw);
            matmul(
                &mut z,
                hw,
                false,
                conv.matrix(),
                Op::Plain,
                cols_m,
                Op::Plain,
            );
            // z becomes the ReLU output.
            for (z, b) in z.chunks_exact_mut(hw).zip(&conv.bias) {
                z.iter_mut().for_each(|v| *v = (*v + b).max(0.0));
            }
            // The pool takes the ReLU output plus the skip (the input, zero-padded to CHANNELS
            // channels).
            let (ph, pw) = (h / 2, w / 2);
            let mut pooled = vec![0.0; CHANNELS * ph * pw];
            let mut argmax = vec![0u32; CHANNELS * ph * pw];
            for c in 0..CHANNELS {
                let value = |p: usize| {
                    let at = c * hw + p;
                    if c < conv.c_in {
                        z[at] + x[at]
                    } else {
                        z[at]
                    }
                };
                for y in 0..ph {
                    for xo in 0..pw {
                        let at = (c * ph + y) * pw + xo;
                        // The first of the window's maxima, in row order.
                        let window = [0, 1, w, w + 1].map(|d| 2 * y * w + 2 * xo + d);
                        let (best, max) = window
                            .map(|p| (p, value(p)))
                            .into_iter()
                            .reduce(|a, b| if b.1 > a.1 { b } else { a })
                            .expect("a 2×2 window");
                        pooled[at] = max;
                        argmax[at] = best as u32;
                    }
                }
            }
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
    pub fn backward(&self, pass: &EncoderPass, d_codes: &[f32]) -> HostEncoder {
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

    fn view_backward(&self, tape: &ViewTape, d_code: &[f32]) -> HostEncoder {
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
        let mut cols = Vec::new();
        let mut d_cols = Vec::new();
        for (b, conv) in self.convs.iter().enumerate().rev() {
            let x = &tape.inputs[b];
            let (h, w) = tape.sizes[b];
            let hw = h * w;
            // Through the pool: each output's gradient to the value it took.
            let mut d_sum = vec![0.0; CHANNELS * hw];
            let pooled = hw / 4;
            for (i, (&d, &src)) in d_out.iter().zip(&tape.argmax[b]).enumerate() {
                d_sum[(i / pooled) * hw + src as usize] = d;
            }
            // The skip passes the gradient to the input as it is; block 0's input is the map.
            let mut d_x = if b > 0 {
                d_sum[..conv.c_in * hw].to_vec()
            } else {
                Vec::new()
            };
            // Through the ReLU, then the bias's gradient.
            let grads = &mut g.convs[b];
            for (c, (d, r)) in d_sum
                .chunks_exact_mut(hw)
                .zip(tape.relu[b].chunks_exact(hw))
                .enumerate()
            {
                d.iter_mut()
                    .zip(r)
                    .for_each(|(d, &r)| *d = if r > 0.0 { *d } else { 0.0 });
                grads.bias[c] = d.iter().map(|&v| v as f64).sum::<f64>() as f32;
            }
            unfold(x, conv.c_in, h, w, &mut cols);
            let d_z = MatRef::new(&d_sum, CHANNELS, hw);
            let cols_m = MatRef::new(&cols, conv.c_in * TAPS, hw);
            let k = conv.c_in * TAPS;
            matmul(
                &mut grads.weight,
                k,
                false,
                d_z,
                Op::Plain,
                cols_m,
                Op::Transposed,
            );
            if b > 0 {
                d_cols.resize(k * hw, 0.0);
                matmul(
                    &mut d_cols,
                    hw,
                    false,
                    conv.matrix(),
                    Op::Transposed,
                    d_z,
                    Op::Plain,
                );
                fold_add(&d_cols, h, w, &mut d_x);
            }
            d_out = d_x;
        }
        g
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unfolding and folding back are adjoint: ⟨unfold(x), c⟩ = ⟨x, fold(c)⟩.
    #[test]
    fn folding_is_the_adjoint_of_unfolding() {
        let (c_in, h, w) = (2, 3, 5);
        let x: Vec<f32> = (0..c_in * h * w).map(|i| (i as f32 * 0.37).sin()).collect();
        let c: Vec<f32> = (0..c_in * TAPS * h * w)
            .map(|i| (i as f32 * 0.91).cos())
            .collect();
        let mut cols = Vec::new();
        unfold(&x, c_in, h, w, &mut cols);
        let mut back = vec![0.0; x.len()];
        fold_add(&c, h, w, &mut back);
        let left: f64 = cols.iter().zip(&c).map(|(a, b)| (a * b) as f64).sum();
        let right: f64 = x.iter().zip(&back).map(|(a, b)| (a * b) as f64).sum();
        assert!((left - right).abs() < 1e-5, "{left} against {right}");
        // The centre tap is the map itself; the top-left one is shifted down and right.
        assert_eq!(&cols[4 * h * w..5 * h * w], &x[..h * w]);
        assert_eq!(cols[w + 1], x[0]);
        assert_eq!(cols[0], 0.0);
    }
}
