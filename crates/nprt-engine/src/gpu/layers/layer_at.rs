//! Where a layer's tensors lie in a network's flat parameter buffers (`ParameterLayout`), and
//! its shape: what every recorded dispatch addresses a layer by.

use crate::layers::conv::Conv;
use crate::layers::dense::Dense;
use nprt_gpu::Span;

/// One dense layer's place in the flat buffers.
pub struct DenseAt {
    pub weight: Span,
    pub bias: Span,
    pub d_in: usize,
    pub d_out: usize,
}

impl DenseAt {
    /// `dense`'s place, its weight's and bias's spans taken in order from `spans`.
    pub fn new(dense: &Dense, spans: &mut impl Iterator<Item = Span>) -> Self {
        DenseAt {
            weight: spans.next().expect("a span per tensor"),
            bias: spans.next().expect("a span per tensor"),
            d_in: dense.d_in,
            d_out: dense.d_out,
        }
    }
}

/// One convolution in the flat buffers, and its shape.
pub struct ConvAt {
    pub weight: Span,
    pub bias: Span,
    pub c_in: usize,
    pub c_out: usize,
    /// The kernel's side (3, or 1).
    pub k: usize,
}

impl ConvAt {
    /// `conv`'s place, its weight's and bias's spans taken in order from `spans`.
    pub fn new(conv: &Conv, spans: &mut impl Iterator<Item = Span>) -> Self {
        ConvAt {
            weight: spans.next().expect("a span per tensor"),
            bias: spans.next().expect("a span per tensor"),
            c_in: conv.c_in,
            c_out: conv.c_out,
            k: conv.k,
        }
    }
}
