enable f16;

// A dense layer's weight gradient in a mixed-precision training step: xᵀ·dz summed over the
// batch's rows, x (rows × k_pad) and dz (rows × n_pad) held as f16 with zeros past the batch's
// rows, the sums in f32. The rows are cut into chunks of `chunk` (a multiple of 16); chunk c's
// m × n sums go to their own block of `partial` (from c · m' · n, row stride n), which a column
// sum then adds in order. With `bias` set, the block has a row m' = m + 1 more: dz's column
// sums over the chunk, the bias's gradient, made here so that it costs no dispatches of its
// own (a column sum over the batch's rows took three). What both of its products share: the
// parameters, the buffers, the bias's sums and where a sum goes. The product is `half_weight_grad_coop` (tensor cores) where the adapter has
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
    // 1: the bias's gradient as the block's row m.
    bias: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> p: HalfWeightGrad;
@group(0) @binding(1) var<storage, read> x: array<f16>;
@group(0) @binding(2) var<storage, read> dz: array<f16>;
@group(0) @binding(3) var<storage, read_write> partial: array<f32>;

// The chunk of rows this invocation sums.
var<private> chunk_of: u32;

fn finish(i: u32, j: u32, sum: f32) {
    let rows = p.m + p.bias;
    if (i < rows && j < p.n) {
        partial[chunk_of * rows * p.n + i * p.n + j] = sum;
    }
}

// dz's column j summed over rows r0..r1: a share of the bias's gradient.
fn dz_sum(j: u32, r0: u32, r1: u32) -> f32 {
    var sum = 0.0;
    for (var r = r0; r < r1; r++) {
        sum += f32(dz[r * p.n_pad + j]);
    }
    return sum;
}
