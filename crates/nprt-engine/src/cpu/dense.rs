//! An [`Mlp`] on the CPU engine: forward over a block of rows keeping what backward needs, and
//! backward into parameter gradients. Bias and activation are one pass after each matrix
//! product, and a SIREN layer computes its derivative (ω0·cos) in the same pass as its value.

use std::ops::Range;

use super::matmul::{matmul, MatRef, Op};
use super::sincos::{sin_scaled, sincos_scaled};
use crate::layers::activation::{Activation, OMEGA_0};
use crate::layers::dense::Dense;
use crate::layers::mlp::Mlp;

/// An input of layer 0 that rows share in groups (the light code: one per view), multiplied by
/// its weight rows once per group instead of once per row.
#[derive(Clone)]
pub struct SharedInput<'a> {
    /// The rows of layer 0's weight it multiplies: the first or the last ones; the per-row
    /// input multiplies the others.
    pub weight_rows: Range<usize>,
    /// `groups × weight_rows.len()` values.
    pub values: &'a [f32],
    /// Each row's group.
    pub group: &'a [u32],
}

impl SharedInput<'_> {
    fn groups(&self) -> usize {
        self.values.len() / self.weight_rows.len()
    }
}

/// Whether a forward pass keeps what backward needs (training) or only the outputs (inference).
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Pass {
    Train,
    Infer,
}

/// What a forward pass over a block of rows keeps: each layer's output and, for hidden layers
/// of a training pass, its activation's derivative at the pre-activation (ReLU needs none: its
/// output says it). Its buffers are reused from block to block.
#[derive(Default)]
pub struct Tape {
    outputs: Vec<Vec<f32>>,
    slopes: Vec<Vec<f32>>,
    /// The shared input's product with its weight rows, `groups × d_out`.
    shared: Vec<f32>,
    scratch: Vec<f32>,
    rows: usize,
}

impl Tape {
    /// The last layer's output, `rows × d_out`.
    pub fn output(&self) -> &[f32] {
        self.outputs.last().map_or(&[], |o| o.as_slice())
    }
}

impl Dense {
    /// The weight rows `rows` as a matrix.
    fn rows(&self, rows: Range<usize>) -> MatRef<'_> {
        MatRef::new(
            &self.weight[rows.start * self.d_out..rows.end * self.d_out],
            rows.len(),
            self.d_out,
        )
    }

    /// The weight rows the per-row input multiplies when `shared` takes the others.
    fn own_rows(&self, shared: Option<&SharedInput>) -> Range<usize> {
        match shared {
            None => 0..self.d_in,
            Some(s) if s.weight_rows.start == 0 => s.weight_rows.end..self.d_in,
            Some(s) => 0..s.weight_rows.start,
        }
    }
}

impl Mlp {
    /// Runs the rows of `x` (with `shared`, the rest of layer 0's input) through every layer,
    /// keeping what [`Self::backward`] needs when `pass` is [`Pass::Train`].
    pub fn forward(&self, x: MatRef, shared: Option<&SharedInput>, tape: &mut Tape, pass: Pass) {
        let n = self.layers.len();
        tape.outputs.resize_with(n, Vec::new);
        tape.slopes.resize_with(n, Vec::new);
        tape.rows = x.rows;
        if let Some(s) = shared {
            let first = &self.layers[0];
            tape.shared.resize(s.groups() * first.d_out, 0.0);
            let values = MatRef::new(s.values, s.groups(), s.weight_rows.len());
            let w = first.rows(s.weight_rows.clone());
            matmul(
                &mut tape.shared,
                first.d_out,
                false,
                values,
                Op::Plain,
                w,
                Op::Plain,
            );
        }
        for (l, layer) in self.layers.iter().enumerate() {
            let (done, rest) = tape.outputs.split_at_mut(l);
            let (input, w) = if l == 0 {
                (x, layer.rows(layer.own_rows(shared)))
            } else {
                let x = MatRef::new(&done[l - 1], x.rows, layer.d_in);
                (x, layer.rows(0..layer.d_in))
            };
            let hidden = l + 1 < n;
            let siren = hidden && self.activation == Activation::Siren;
            // A SIREN layer's product goes to the slope buffer, which then receives ω0·cos
            // (for backward only: inference takes the sine in place).
            let z = if siren && pass == Pass::Train {
                &mut tape.slopes[l]
            } else {
                &mut rest[0]
            };
            z.resize(x.rows * layer.d_out, 0.0);
            matmul(z, layer.d_out, false, input, Op::Plain, w, Op::Plain);
            for (r, row) in z.chunks_exact_mut(layer.d_out).enumerate() {
                row.iter_mut().zip(&layer.bias).for_each(|(v, b)| *v += b);
                if let (0, Some(s)) = (l, shared) {
                    let g = s.group[r] as usize * layer.d_out;
                    let add = &tape.shared[g..g + layer.d_out];
                    row.iter_mut().zip(add).for_each(|(v, a)| *v += a);
                }
                if hidden && self.activation == Activation::Relu {
                    row.iter_mut().for_each(|v| *v = v.max(0.0));
                }
            }
            match (siren, pass) {
                (false, _) => {}
                (true, Pass::Infer) => sin_scaled(&mut rest[0], OMEGA_0),
                (true, Pass::Train) => {
                    let out = &mut rest[0];
                    out.resize(x.rows * layer.d_out, 0.0);
                    sincos_scaled(&mut tape.slopes[l], OMEGA_0, out);
                }
            }
        }
    }

    /// Back-propagates `d_output` (the loss's gradient at the last layer's output, overwritten)
    /// through the layers of a forward pass over `x` and `shared`, adding parameter gradients
    /// to `grads`; if asked, writes the gradient at the per-row input into `d_input`
    /// (`rows × x.cols`) and adds the gradient at the shared input to `d_shared`
    /// (`groups × shared width`).
    #[allow(clippy::too_many_arguments)]
    pub fn backward(
        &self,
        x: MatRef,
        shared: Option<&SharedInput>,
        tape: &mut Tape,
        d_output: &mut Vec<f32>,
        grads: &mut Mlp,
        mut d_input: Option<&mut [f32]>,
        mut d_shared: Option<&mut [f32]>,
    ) {
        let rows = tape.rows;
        let mut dy = std::mem::take(d_output);
        let mut dx = std::mem::take(&mut tape.scratch);
        for l in (0..self.layers.len()).rev() {
            let layer = &self.layers[l];
            let g = &mut grads.layers[l];
            // One pass: the activation's derivative, then the bias gradient (a column sum).
            let hidden = l + 1 < self.layers.len();
            let w = layer.d_out;
            for (r, row) in dy.chunks_exact_mut(w).enumerate() {
                match (hidden, self.activation) {
                    (false, _) => {}
                    (true, Activation::Siren) => {
                        let s = &tape.slopes[l][r * w..(r + 1) * w];
                        row.iter_mut().zip(s).for_each(|(d, s)| *d *= s);
                    }
                    (true, Activation::Relu) => {
                        let y = &tape.outputs[l][r * w..(r + 1) * w];
                        row.iter_mut()
                            .zip(y)
                            .for_each(|(d, &y)| *d = if y > 0.0 { *d } else { 0.0 });
                    }
                }
                g.bias.iter_mut().zip(row.iter()).for_each(|(b, d)| *b += d);
            }
            let dz = MatRef::new(&dy, rows, layer.d_out);
            if l > 0 {
                let input = MatRef::new(&tape.outputs[l - 1], rows, layer.d_in);
                matmul(
                    &mut g.weight,
                    layer.d_out,
                    true,
                    input,
                    Op::Transposed,
                    dz,
                    Op::Plain,
                );
                dx.resize(rows * layer.d_in, 0.0);
                let w = layer.rows(0..layer.d_in);
                matmul(&mut dx, layer.d_in, false, dz, Op::Plain, w, Op::Transposed);
                std::mem::swap(&mut dx, &mut dy);
                continue;
            }
            let own = layer.own_rows(shared);
            let g_own = &mut g.weight[own.start * layer.d_out..own.end * layer.d_out];
            matmul(g_own, layer.d_out, true, x, Op::Transposed, dz, Op::Plain);
            if let Some(d_in) = d_input.as_deref_mut() {
                let w = layer.rows(own);
                matmul(d_in, x.cols, false, dz, Op::Plain, w, Op::Transposed);
            }
            if let Some(s) = shared {
                shared_backward(layer, s, &dy, &mut dx, g, d_shared.as_deref_mut());
            }
        }
        *d_output = dy;
        tape.scratch = dx;
    }
}

/// The first layer's backward pass through a shared input `s`: per group the sum of its rows'
/// gradients `dy` (into the scratch `dx`), then the weight gradient of the shared rows (added
/// to `g`) and, if asked, the gradient at the shared input (added to `d_shared`).
fn shared_backward(
    layer: &Dense,
    s: &SharedInput,
    dy: &[f32],
    dx: &mut Vec<f32>,
    g: &mut Dense,
    d_shared: Option<&mut [f32]>,
) {
    let width = layer.d_out;
    dx.clear();
    dx.resize(s.groups() * width, 0.0);
    for (row, &grp) in dy.chunks_exact(width).zip(s.group) {
        let at = grp as usize * width;
        dx[at..at + width]
            .iter_mut()
            .zip(row)
            .for_each(|(a, d)| *a += d);
    }
    let sums = MatRef::new(dx, s.groups(), width);
    let values = MatRef::new(s.values, s.groups(), s.weight_rows.len());
    let rows = s.weight_rows.clone();
    let g_shared = &mut g.weight[rows.start * width..rows.end * width];
    matmul(
        g_shared,
        width,
        true,
        values,
        Op::Transposed,
        sums,
        Op::Plain,
    );
    if let Some(d) = d_shared {
        let w = layer.rows(s.weight_rows.clone());
        matmul(
            d,
            s.weight_rows.len(),
            true,
            sums,
            Op::Plain,
            w,
            Op::Transposed,
        );
    }
}
