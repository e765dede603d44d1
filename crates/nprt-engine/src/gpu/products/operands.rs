//! What a product on the device reads and writes: its operands (strided matrices in a buffer),
//! the bias its epilogue adds, and where its output goes.

use nprt_gpu::GpuDevice;

/// One operand of a product: element (i, k) at `offset + i · rows + k · cols` of `buffer`;
/// for a left operand, `ones_row`'s elements read as ones instead.
pub struct Operand<'a> {
    pub buffer: &'a wgpu::Buffer,
    pub offset: usize,
    pub rows: usize,
    pub cols: usize,
    pub ones_row: Option<usize>,
}

impl<'a> Operand<'a> {
    /// A row-major matrix with `stride` values per row, from `offset`.
    pub fn plain(buffer: &'a wgpu::Buffer, offset: usize, stride: usize) -> Self {
        Operand {
            buffer,
            offset,
            rows: stride,
            cols: 1,
            ones_row: None,
        }
    }

    /// The transpose of a row-major matrix with `stride` values per row.
    pub fn transposed(buffer: &'a wgpu::Buffer, offset: usize, stride: usize) -> Self {
        Operand {
            buffer,
            offset,
            rows: 1,
            cols: stride,
            ones_row: None,
        }
    }
}

/// What a product adds before its activation.
#[derive(Clone, Copy)]
pub enum Bias<'a> {
    None,
    /// `d_out` values from an offset of a buffer.
    Column(&'a wgpu::Buffer, usize),
    /// One row of `d_out` values per group, and each row's group.
    Group(&'a wgpu::Buffer, &'a wgpu::Buffer),
}

impl<'a> Bias<'a> {
    /// What a kernel's epilogue takes: its mode (0 none, 1 column, 2 group), its buffer, its
    /// offset there and the rows' groups (`gpu`'s empty buffer for what is unused).
    pub fn binding(self, gpu: &'a GpuDevice) -> (usize, &'a wgpu::Buffer, usize, &'a wgpu::Buffer) {
        match self {
            Bias::None => (0, &gpu.empty, 0, &gpu.empty),
            Bias::Column(buffer, offset) => (1, buffer, offset, &gpu.empty),
            Bias::Group(buffer, group) => (2, buffer, 0, group),
        }
    }
}

/// A product's output: `rows` values apart from `offset` of `buffer`, written or added to.
/// For a column sum, `tail` sends the sums from its index on elsewhere.
pub struct Output<'a> {
    pub buffer: &'a wgpu::Buffer,
    pub offset: usize,
    pub stride: usize,
    pub accumulate: bool,
    pub tail: Option<Tail<'a>>,
}

/// A column sum's sums from index `at` (> 0) on, sent to `offset` of `buffer` (which may be
/// the output's own).
#[derive(Clone, Copy)]
pub struct Tail<'a> {
    pub at: usize,
    pub buffer: &'a wgpu::Buffer,
    pub offset: usize,
}

impl<'a> Output<'a> {
    pub fn to(buffer: &'a wgpu::Buffer, offset: usize, stride: usize) -> Self {
        Output {
            buffer,
            offset,
            stride,
            accumulate: false,
            tail: None,
        }
    }
}
