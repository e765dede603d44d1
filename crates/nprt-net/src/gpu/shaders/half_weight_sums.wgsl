enable f16;

// A dense layer's weight gradient in a mixed-precision training step: xᵀ·dz summed over the
// batch's rows, x (rows × k_pad) and dz (rows × n_pad) held as f16 with zeros past the batch's
// rows, the sums in f32. The rows are cut into chunks of `chunk` (a multiple of 16); chunk c's
// m × n sums go to their own block of `partial` (from c · m · n, row stride n), which a column
// sum then adds in order. What both of its products share: the parameters, the buffers and
// where a sum goes. The product is `half_weight_grad_coop` (tensor cores) where the adapter has
// cooperative matrices and `half_weight_grad` elsewhere.

struct HalfWeightGrad {
    // The batch's rows padded to a multiple of 16 (x and dz hold at least these).
    rows: u32,
    chunk: u32,
    // The gradient's rows (x's columns) and columns (dz's).
    m: u32,
    n: u32,
    k_pad: u32,
    n_pad: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> p: HalfWeightGrad;
@group(0) @binding(1) var<storage, read> x: array<f16>;
@group(0) @binding(2) var<storage, read> dz: array<f16>;
@group(0) @binding(3) var<storage, read_write> partial: array<f32>;

// The chunk of rows this invocation sums.
var<private> chunk_of: u32;

fn finish(i: u32, j: u32, sum: f32) {
    if (i < p.m && j < p.n) {
        partial[chunk_of * p.m * p.n + i * p.n + j] = sum;
    }
}
