//! A [`Conv`] on the CPU engine: one matrix product over the input unfolded into its k×k
//! neighbourhoods (im2col), and its adjoint. The light encoder and the Deep Shading U-Net run
//! every convolution through it.

use super::accumulate;
use super::matmul::{matmul, MatRef, Op};
use crate::layers::conv::Conv;

/// The source column of output column `x` under horizontal tap `kx` of a 3×3 kernel, if inside
/// the image.
fn source(x: usize, kx: usize, w: usize) -> Option<usize> {
    (x + kx).checked_sub(1).filter(|&s| s < w)
}

/// The 3×3 neighbourhoods of `x` (c_in × h × w) as the rows of a (c_in · 9) × (h · w) matrix,
/// zero outside the image: row c · 9 + ky · 3 + kx holds x[c][y + ky − 1][x + kx − 1].
fn unfold(x: &[f32], c_in: usize, h: usize, w: usize, cols: &mut Vec<f32>) {
    cols.clear();
    cols.resize(c_in * 9 * h * w, 0.0);
    for (row, dst) in cols.chunks_exact_mut(h * w).enumerate() {
        let (c, ky, kx) = (row / 9, row % 9 / 3, row % 3);
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
        let (c, ky, kx) = (row / 9, row % 9 / 3, row % 3);
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

impl Conv {
    fn matrix(&self) -> MatRef<'_> {
        MatRef::new(&self.weight, self.c_out, self.c_in * self.k * self.k)
    }

    /// `x` (c_in × h × w) as the product's right-hand side: unfolded into `cols`, or as it is
    /// for a 1×1 kernel.
    fn columns<'a>(&self, x: &'a [f32], h: usize, w: usize, cols: &'a mut Vec<f32>) -> &'a [f32] {
        match self.k {
            1 => x,
            3 => {
                unfold(x, self.c_in, h, w, cols);
                cols
            }
            k => unreachable!("{k}×{k} kernels are not built"),
        }
    }

    /// The convolution of `x` (c_in × h × w) plus the bias, c_out × h × w; `cols` is scratch.
    pub fn forward(&self, x: &[f32], h: usize, w: usize, cols: &mut Vec<f32>) -> Vec<f32> {
        let hw = h * w;
        let mut z = vec![0.0; self.c_out * hw];
        let k = self.c_in * self.k * self.k;
        let x = MatRef::new(self.columns(x, h, w, cols), k, hw);
        matmul(&mut z, hw, false, self.matrix(), Op::Plain, x, Op::Plain);
        for (z, b) in z.chunks_exact_mut(hw).zip(&self.bias) {
            z.iter_mut().for_each(|v| *v += b);
        }
        z
    }

    /// Given the gradient `d_z` at the output of [`Self::forward`] on `x`, sets `g`'s weight and
    /// bias gradients and, if asked, adds the gradient at `x` to `d_x`.
    pub fn backward(
        &self,
        x: &[f32],
        (h, w): (usize, usize),
        d_z: &[f32],
        g: &mut Conv,
        d_x: Option<&mut [f32]>,
    ) {
        let hw = h * w;
        for (b, d) in g.bias.iter_mut().zip(d_z.chunks_exact(hw)) {
            *b = d.iter().map(|&v| v as f64).sum::<f64>() as f32;
        }
        let k = self.c_in * self.k * self.k;
        let mut cols = Vec::new();
        let x = MatRef::new(self.columns(x, h, w, &mut cols), k, hw);
        let d_z = MatRef::new(d_z, self.c_out, hw);
        matmul(&mut g.weight, k, false, d_z, Op::Plain, x, Op::Transposed);
        let Some(d_x) = d_x else { return };
        let mut d_cols = vec![0.0; k * hw];
        matmul(
            &mut d_cols,
            hw,
            false,
            self.matrix(),
            Op::Transposed,
            d_z,
            Op::Plain,
        );
        match self.k {
            1 => accumulate(d_x, &d_cols),
            _ => fold_add(&d_cols, h, w, d_x),
        }
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
        let c: Vec<f32> = (0..c_in * 9 * h * w)
            .map(|i| (i as f32 * 0.91).cos())
            .collect();
        let mut cols = Vec::new();
        unfold(&x, c_in, h, w, &mut cols);
        let mut back = vec![0.0; x.len()];
        fold_add(&c, h, w, &mut back);
        let left: f64 = cols.iter().zip(&c).map(|(a, b)| (a * b) as f64).sum();
        let right: f64 = x.iter().zip(&back).map(|(a, b)| (a * b) as f64).sum();
        assert!((left - right).abs() < 1e-5, "{left} against {right}");
        // The centre tap is the image itself; the top-left one is shifted down and right.
        assert_eq!(&cols[4 * h * w..5 * h * w], &x[..h * w]);
        assert_eq!(cols[w + 1], x[0]);
        assert_eq!(cols[0], 0.0);
    }
}
