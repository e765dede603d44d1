enable f16;

// A dense layer's product in a mixed-precision training step (`--precision f16`): x (rows ×
// k_pad) and W (k_pad × n_pad) held as f16 as `half_layer` holds them, the sums kept in f32,
// under `gemm`'s epilogue. Forward, it adds a bias (per column, or per row group: the light
// code's share of a shading network's first layer, one per view), keeps the pre-activation in
// z and applies linear/ReLU/SIREN. Backward (dx = dz·Wᵀ, W held transposed), it multiplies by
// ReLU's or SIREN's derivative at the pre-activation z holds. It writes f16 rows padded to
// n_pad (the next product's operand; zeros past n and past rows, so that a sum over the padded
// rows adds nothing), f32 rows of n (the loss, a bias's gradient, a network's input
// gradient), or both. f16 values saturate at ±65504 rather than overflow to infinity.

struct HalfTrainLayer {
    rows: u32,
    n: u32,
    n_pad: u32,
    k_pad: u32,
    w_off: u32,
    // 0: linear, 1: ReLU, 2: SIREN, sin(30 v); 3: v · (z > 0), 4: v · 30 cos(30 z).
    activation: u32,
    // 0: none, 1: bias[bias_off + j], 2: bias[group[i] · n + j].
    bias: u32,
    bias_off: u32,
    // 1: write the pre-activation to z (rows × n).
    keep_z: u32,
    // 1: write y16 (rows of n_pad f16 values, up to the rows the product covers); 1: write y32
    // (rows of n f32 values).
    out16: u32,
    out32: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> p: HalfTrainLayer;
@group(0) @binding(1) var<storage, read> x: array<f16>;
@group(0) @binding(2) var<storage, read> w: array<f16>;
@group(0) @binding(3) var<storage, read> bias: array<f32>;
@group(0) @binding(4) var<storage, read> group_of: array<u32>;
@group(0) @binding(5) var<storage, read_write> z: array<f32>;
@group(0) @binding(6) var<storage, read_write> y16: array<f16>;
@group(0) @binding(7) var<storage, read_write> y32: array<f32>;

const OMEGA_0: f32 = 30.0;
const ROWS: u32 = 256u;
const COLS: u32 = 64u;
const F16_MAX: f32 = 65504.0;

fn finish(i: u32, j: u32, sum: f32) {
    if (j >= p.n_pad) {
        return;
    }
    var v = 0.0;
    if (i < p.rows && j < p.n) {
        v = sum;
        if (p.bias == 1u) {
            v += bias[p.bias_off + j];
        } else if (p.bias == 2u) {
            v += bias[p.bias_off + group_of[i] * p.n + j];
        }
        let at = i * p.n + j;
        if (p.keep_z == 1u) {
            z[at] = v;
        }
        if (p.activation == 1u) {
            v = max(v, 0.0);
        } else if (p.activation == 2u) {
            v = sin(OMEGA_0 * v);
        } else if (p.activation == 3u) {
            v = select(0.0, v, z[at] > 0.0);
        } else if (p.activation == 4u) {
            v *= OMEGA_0 * cos(OMEGA_0 * z[at]);
        }
        if (p.out32 == 1u) {
            y32[at] = v;
        }
    }
    if (p.out16 == 1u) {
        y16[i * p.n_pad + j] = f16(clamp(v, -F16_MAX, F16_MAX));
    }
}
