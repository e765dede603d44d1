enable f16;

// A whole MLP's forward pass in half precision in one dispatch (a frame's, and a training
// step's, which also keeps what backward reads; after tiny-cuda-nn's fully fused MLP): a
// workgroup takes 64 rows through every layer, their activations held in workgroup memory as
// f16 between layers instead of written out and read back, the sums kept in f32. The weights
// are the layers' f16 copies in one buffer (`half_layer`'s layout: k_pad rows of n_pad values,
// 16 rows of zeros past them). What both of its products share: the parameters, the buffers,
// the input's staging and the epilogue. The product is `half_mlp_coop` (tensor cores) where
// the adapter has cooperative matrices and `half_mlp_plain` elsewhere.

struct HalfMlp {
    rows: u32,
    layers: u32,
    // 1: x32 holds the input, f32 rows of x_cols values, made f16 as they are staged; 0: x16
    // does, f16 rows of the first layer's k_pad values.
    x_f32: u32,
    x_cols: u32,
    // What the last layer writes: 1 in out16, f16 rows of its n_pad values from its at.z of y16
    // (the next network's input, or a backward pass's gradient at the first layer's output);
    // 1 in out32, f32 rows of its n values in y32.
    out16: u32,
    out32: u32,
    // 1 (a training step's pass): the input is also kept, as f16 rows from in_at of y16, and
    // each hidden layer's output, as f16 rows from its at.z of y16.
    keep: u32,
    // 1 (a training step's forward pass): each hidden layer's pre-activation is kept, f32 rows
    // of n from its at.w of z, which a backward pass's derivatives read there.
    keep_z: u32,
    in_at: u32,
    // The first layer's bias: 0 none; 1 bias0[bias0_at + j]; 2 bias0[group_of[i] · n + j] (the
    // light code's share of a shading network's first layer in training, a row per view).
    bias0_mode: u32,
    bias0_at: u32,
    // 1: the other layers add their bias from bias; 0 (a backward pass): none.
    hidden_bias: u32,
    // Per layer: its input's padded width k_pad, its outputs n, their padding n_pad (both
    // multiples of 16, at most ACT), its activation: 0 linear, 1 ReLU, 2 SIREN, sin(30 v);
    // backward, times the derivative at the pre-activation z holds: 3 ReLU's, 4 SIREN's.
    shape: array<vec4<u32>, 8>,
    // Per layer: where its weight starts in w, its bias in bias (layer 0's is bias0's), its f16
    // output in y16 and its pre-activation in z.
    at: array<vec4<u32>, 8>,
}

@group(0) @binding(0) var<uniform> p: HalfMlp;
@group(0) @binding(1) var<storage, read> x16: array<f16>;
@group(0) @binding(2) var<storage, read> x32: array<f32>;
@group(0) @binding(3) var<storage, read> w: array<f16>;
@group(0) @binding(4) var<storage, read> bias0: array<f32>;
@group(0) @binding(5) var<storage, read> bias: array<f32>;
@group(0) @binding(6) var<storage, read> group_of: array<u32>;
@group(0) @binding(7) var<storage, read_write> y16: array<f16>;
@group(0) @binding(8) var<storage, read_write> y32: array<f32>;
@group(0) @binding(9) var<storage, read_write> z: array<f32>;

const OMEGA_0: f32 = 30.0;
const F16_MAX: f32 = 65504.0;
// Rows a workgroup takes through the MLP, its threads, and the widest layer it holds.
const MLP_ROWS: u32 = 64u;
const THREADS: u32 = 128u;
const ACT: u32 = 256u;

// The workgroup's rows of the layer being computed: its input, then (once every thread has
// read it) its output, the next layer's input.
var<workgroup> act: array<f16, 16384>;
// The workgroup's first row, and the layer the epilogue finishes.
var<private> row0: u32;
var<private> layer: u32;

// The workgroup's rows of the input into `act`, zeros past the input's columns (and, for an
// f32 input, past its rows).
fn stage_input(t: u32) {
    let k_pad = p.shape[0].x;
    for (var e = t; e < MLP_ROWS * k_pad; e += THREADS) {
        let r = e / k_pad;
        let k = e % k_pad;
        let i = row0 + r;
        var v = f16(0.0);
        if (p.x_f32 == 0u) {
            v = x16[i * k_pad + k];
        } else if (i < p.rows && k < p.x_cols) {
            v = f16(clamp(x32[i * p.x_cols + k], -F16_MAX, F16_MAX));
        }
        act[r * ACT + k] = v;
        if (p.keep == 1u) {
            y16[p.in_at + i * k_pad + k] = v;
        }
    }
}

// Finishes the current layer's output (r, j), r among the workgroup's rows, from its sum: into
// `act` for the next layer (and, in training, the tape), the last layer's into y16 and/or y32.
// Padding columns and rows past the batch get zeros, so that the next layer's padded k adds
// nothing, nor a weight's gradient summed over the held rows. f16 values saturate at ±65504
// rather than overflow to infinity.
fn finish(r: u32, j: u32, sum: f32) {
    let s = p.shape[layer];
    if (j >= s.z) {
        return;
    }
    let i = row0 + r;
    let hidden = layer + 1u < p.layers;
    let live = i < p.rows && j < s.y;
    var v = 0.0;
    if (live) {
        v = sum;
        if (layer > 0u) {
            if (p.hidden_bias == 1u) {
                v += bias[p.at[layer].y + j];
            }
        } else if (p.bias0_mode == 1u) {
            v += bias0[p.bias0_at + j];
        } else if (p.bias0_mode == 2u) {
            v += bias0[group_of[i] * s.y + j];
        }
        let at_z = p.at[layer].w + i * s.y + j;
        if (p.keep_z == 1u && hidden) {
            z[at_z] = v;
        }
        if (s.w == 1u) {
            v = max(v, 0.0);
        } else if (s.w == 2u) {
            v = sin(OMEGA_0 * v);
        } else if (s.w == 3u) {
            v = select(0.0, v, z[at_z] > 0.0);
        } else if (s.w == 4u) {
            v *= OMEGA_0 * cos(OMEGA_0 * z[at_z]);
        }
    }
    let h = f16(clamp(v, -F16_MAX, F16_MAX));
    let at16 = p.at[layer].z + i * s.z + j;
    if (hidden) {
        act[r * ACT + j] = h;
        if (p.keep == 1u) {
            y16[at16] = h;
        }
        return;
    }
    if (p.out16 == 1u) {
        y16[at16] = h;
    }
    if (p.out32 == 1u && live) {
        y32[i * s.y + j] = v;
    }
}
