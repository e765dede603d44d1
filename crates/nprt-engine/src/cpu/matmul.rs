//! Row-major f32 matrix products through the `gemm` family's f32 kernels (`gemm-f32`), with
//! either operand read transposed through its strides instead of copied.

/// A row-major matrix view: `rows × cols` values, row `r` starting at `r · stride`.
#[derive(Clone, Copy)]
pub struct MatRef<'a> {
    pub data: &'a [f32],
    pub rows: usize,
    pub cols: usize,
    pub stride: usize,
}

impl<'a> MatRef<'a> {
    #[inline]
    pub fn new(data: &'a [f32], rows: usize, cols: usize) -> Self {
        MatRef {
            data,
            rows,
            cols,
            stride: cols,
        }
    }

    fn check(&self) {
        assert!(self.cols <= self.stride || self.rows <= 1);
        assert!(self.rows == 0 || (self.rows - 1) * self.stride + self.cols <= self.data.len());
    }
}

/// How an operand enters the product.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Op {
    Plain,
    Transposed,
}

/// `dst = a·b` (or `dst += a·b` when `accumulate`), with `a` and `b` each taken as given or
/// transposed; `dst` is row-major `m × n` with row stride `dst_stride`.
pub fn matmul(
    dst: &mut [f32],
    dst_stride: usize,
    accumulate: bool,
    a: MatRef,
    a_op: Op,
    b: MatRef,
    b_op: Op,
) {
    a.check();
    b.check();
    // (rows, cols, row stride, column stride) of each operand as used.
    let view = |x: MatRef, op: Op| match op {
        Op::Plain => (x.rows, x.cols, x.stride as isize, 1isize),
        Op::Transposed => (x.cols, x.rows, 1isize, x.stride as isize),
    };
    let (m, k, a_rs, a_cs) = view(a, a_op);
    let (k2, n, b_rs, b_cs) = view(b, b_op);
    assert_eq!(k, k2, "inner dimensions differ");
    assert!(n <= dst_stride || m <= 1);
    assert!(m == 0 || (m - 1) * dst_stride + n <= dst.len());
    if m == 0 || n == 0 {
        return;
    }
    if k == 0 {
        if !accumulate {
            for r in 0..m {
                dst[r * dst_stride..r * dst_stride + n].fill(0.0);
            }
        }
        return;
    }
    // The kernels prefer a column-major destination, so a row-major one is computed as its
    // transpose, Cᵀ = Bᵀ·Aᵀ (what the `gemm` crate's front end does before the same call).
    // Each operand as (data, column stride, row stride).
    let (a, b) = ((a.data.as_ptr(), a_cs, a_rs), (b.data.as_ptr(), b_cs, b_rs));
    let stride = dst_stride as isize;
    let (m, n, [dst_cs, dst_rs], lhs, rhs) = match dst_stride > 1 {
        true => (n, m, [stride, 1], (b.0, b.2, b.1), (a.0, a.2, a.1)),
        false => (m, n, [1, stride], a, b),
    };
    // SAFETY: the asserts above keep every index the kernel forms from these shapes and
    // strides inside the three slices, and `dst` is borrowed mutably so it aliases neither
    // operand.
    unsafe {
        gemm_f32::gemm::f32::get_gemm_fn()(
            m,
            n,
            k,
            dst.as_mut_ptr(),
            dst_cs,
            dst_rs,
            accumulate,
            lhs.0,
            lhs.1,
            lhs.2,
            rhs.0,
            rhs.1,
            rhs.2,
            1.0,
            1.0,
            false,
            false,
            false,
            gemm_common::Parallelism::None,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_and_transposes_match_the_definition() {
        let a: Vec<f32> = (0..6).map(|v| v as f32).collect(); // 2×3
        let b: Vec<f32> = (0..12).map(|v| (v as f32) * 0.5 - 2.0).collect(); // 3×4
        let mut c = vec![0.0; 8];
        matmul(
            &mut c,
            4,
            false,
            MatRef::new(&a, 2, 3),
            Op::Plain,
            MatRef::new(&b, 3, 4),
            Op::Plain,
        );
        for i in 0..2 {
            for j in 0..4 {
                let want: f32 = (0..3).map(|k| a[i * 3 + k] * b[k * 4 + j]).sum();
                assert_eq!(c[i * 4 + j], want);
            }
        }
        // aᵀ·a (3×3), accumulated twice.
        let mut g = vec![0.0; 9];
        for _ in 0..2 {
            let a = MatRef::new(&a, 2, 3);
            matmul(&mut g, 3, true, a, Op::Transposed, a, Op::Plain);
        }
        for i in 0..3 {
            for j in 0..3 {
                let want: f32 = 2.0 * (0..2).map(|r| a[r * 3 + i] * a[r * 3 + j]).sum::<f32>();
                assert_eq!(g[i * 3 + j], want);
            }
        }
        // b·bᵀ into the right half of a wider matrix (stride 6).
        let mut d = [-1.0; 18];
        let bm = MatRef::new(&b, 3, 4);
        matmul(&mut d[3..], 6, false, bm, Op::Plain, bm, Op::Transposed);
        for i in 0..3 {
            assert_eq!(&d[i * 6..i * 6 + 3], &[-1.0; 3]);
            for j in 0..3 {
                let want: f32 = (0..4).map(|k| b[i * 4 + k] * b[j * 4 + k]).sum();
                assert_eq!(d[i * 6 + 3 + j], want);
            }
        }
    }
}
