enable f16;

// A dense layer in half precision (the frame path's `--precision f16`): y = act(x·W + bias) with
// x (rows × k_pad) and W (k_pad × n_pad) held as f16, row-major, every row padded with zeros to
// a multiple of 16, and the sums kept in f32. What both of its products share: the parameters,
// the buffers and the epilogue. The product is `half_dense_coop` (tensor cores, through
// cooperative matrices) where the adapter has them and `half_dense` elsewhere; both cover
// 256 rows × 64 columns a workgroup, and both read rows up to the next multiple of 256, which
// the buffers hold.

struct HalfLayer {
    // Rows written (the chunk's), and the padded rows' multiple of 256 that are computed.
    rows: u32,
    // Output columns, and their padding (a multiple of 16) that an f16 output is written to.
    n: u32,
    n_pad: u32,
    // x's columns (a multiple of 16), W's row stride (n_pad), and where W starts (its first
    // row: a shading network's first layer starts past the light code's rows).
    k_pad: u32,
    w_off: u32,
    // 0: linear, 1: ReLU, 2: SIREN, sin(30 v).
    activation: u32,
    // 1: y is f16 with row stride n_pad (the next layer's x); 0: f32 with row stride n.
    half_out: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> p: HalfLayer;
@group(0) @binding(1) var<storage, read> x: array<f16>;
@group(0) @binding(2) var<storage, read> w: array<f16>;
@group(0) @binding(3) var<storage, read> bias: array<f32>;
@group(0) @binding(4) var<storage, read_write> y16: array<f16>;
@group(0) @binding(5) var<storage, read_write> y32: array<f32>;

const OMEGA_0: f32 = 30.0;
const ROWS: u32 = 256u;
const COLS: u32 = 64u;

// Writes output (i, j) from its sum: the padding columns of an f16 output get zeros, so that
// the next layer's padded k adds nothing.
fn finish(i: u32, j: u32, sum: f32) {
    if (j >= p.n_pad) {
        return;
    }
    var v = 0.0;
    if (j < p.n) {
        v = sum + bias[j];
        if (p.activation == 1u) {
            v = max(v, 0.0);
        } else if (p.activation == 2u) {
            v = sin(OMEGA_0 * v);
        }
    }
    if (p.half_out == 1u) {
        y16[i * p.n_pad + j] = f16(v);
    } else if (i < p.rows && j < p.n) {
        y32[i * p.n + j] = v;
    }
}
