//! The CPU kernels: blocked matrix products (gemm), an MLP's fused bias and activation passes
//! with vectorised sin/cos, convolutions as matrix products, pooling and ReLU, and the
//! machine's measured peak. burn's autodiff graph, which they replaced, lost to PyTorch on
//! SIREN designs and spent a third of a step in the encoder's convolutions.

pub mod conv;
pub mod dense;
pub mod matmul;
pub mod peak;
pub mod pool;
pub mod relu;
pub mod sincos;

/// `acc += x`, element by element: gradients summed over blocks, runs and maps.
#[inline]
pub fn accumulate(acc: &mut [f32], x: &[f32]) {
    acc.iter_mut().zip(x).for_each(|(a, v)| *a += v);
}
