enable f16;

// An MLP's weight gradients in a mixed-precision training step, its layers in one dispatch:
// each layer's xᵀ·dz summed over the batch's rows, x (rows × k_pad) and dz (rows × n_pad) held
// as f16 with zeros past the batch's rows, the sums in f32. The rows are cut into chunks of
// `chunk` (a multiple of 16); chunk c's sums, every layer's, go to their own block of `partial`
// (from c · stride), each layer's weight at its w_at (row stride n), laid out as the
// parameters are, so that one column sum adds the chunks in order into every layer's gradient
// at once. With a bias, the layer also sums dz's columns over the chunk, its bias's gradient
// (from b_at), so that it costs no dispatches of its own (a column sum over the batch's rows
// took three); with view sums too, dz's columns over each view's rows of the chunk (a row per
// view from g_at, ending the block past the parameters' span: a first shading layer's, whose
// bias is a row per view, the light code's share). What both of its products share: the
// parameters, the buffers, a work item's layer, the bias's sums and where a sum goes. The
// product is `half_weight_grad_coop` (tensor cores) where the adapter has cooperative matrices
// and `half_weight_grad` elsewhere.

struct HalfWeightGrad {
    // The batch's rows padded to a multiple of 16 (x and dz hold at least these).
    rows: u32,
    chunk: u32,
    layers: u32,
    // A chunk's block of partial: every layer's sums.
    stride: u32,
    // Per layer: the gradient's rows m (x's columns) and columns n (dz's), and the padded
    // widths of x's and dz's rows.
    shape: array<vec4<u32>, 8>,
    // Per layer: where its x rows start in x and its dz rows in dz (f16 values), and where its
    // weight's sums and its bias's start in a chunk's block.
    at: array<vec4<u32>, 8>,
    // Per layer: its first thread of a chunk's (the plain kernel's; the tensor-core kernel
    // takes a row of workgroups a layer), 1 where it has a bias, its views (0: no view sums)
    // and where its view sums start in a chunk's block; past the last layer, the threads a
    // chunk takes.
    work: array<vec4<u32>, 9>,
}

@group(0) @binding(0) var<uniform> p: HalfWeightGrad;
@group(0) @binding(1) var<storage, read> x: array<f16>;
@group(0) @binding(2) var<storage, read> dz: array<f16>;
@group(0) @binding(3) var<storage, read_write> partial: array<f32>;
// Each batch row's view, for view sums.
@group(0) @binding(4) var<storage, read> view: array<u32>;

// The layer and the chunk of rows this invocation sums.
struct Layer {
    m: u32,
    n: u32,
    k_pad: u32,
    n_pad: u32,
    x_at: u32,
    dz_at: u32,
    w_at: u32,
    b_at: u32,
    bias: u32,
    views: u32,
    g_at: u32,
    // This invocation's work item within the layer's share of the chunk (a plain kernel's
    // thread, a tensor-core kernel's workgroup).
    item: u32,
}

var<private> l: Layer;
var<private> chunk_of: u32;

// Layer i, for work item `item` of its share of a chunk.
fn layer_at(i: u32, item: u32) -> Layer {
    let s = p.shape[i];
    let a = p.at[i];
    let w = p.work[i];
    return Layer(s.x, s.y, s.z, s.w, a.x, a.y, a.z, a.w, w.y, w.z, w.w, item);
}

// The layer whose share of a chunk's work items holds `item` (its work items end where the
// next layer's start, the last's at `work[layers]`).
fn layer_of(item: u32) -> Layer {
    var i = 0u;
    while (i + 1u < p.layers && item >= p.work[i + 1u].x) {
        i++;
    }
    return layer_at(i, item - p.work[i].x);
}

// Row i of the layer's sums: the weight's rows, then the bias's (m), then one per view.
fn finish(i: u32, j: u32, sum: f32) {
    if (i < l.m + l.bias + l.views && j < l.n) {
        var at = l.w_at + i * l.n + j;
        if (i == l.m) {
            at = l.b_at + j;
        } else if (i > l.m) {
            at = l.g_at + (i - l.m - 1u) * l.n + j;
        }
        partial[chunk_of * p.stride + at] = sum;
    }
}

// Whether row r counts in sum row i past the weight's (m: every row, the bias's; m + 1 + g:
// view g's rows). The rows past the batch's have zero dz, whatever view they read.
fn counts(r: u32, i: u32) -> bool {
    return i == l.m || view[min(r, arrayLength(&view) - 1u)] == i - l.m - 1u;
}

// dz's column j summed over those of rows r0..r1 that sum row i counts: a share of the bias's
// gradient or of a view's.
fn dz_sum(i: u32, j: u32, r0: u32, r1: u32) -> f32 {
    var sum = 0.0;
    for (var r = r0; r < r1; r++) {
        if (counts(r, i)) {
            sum += f32(dz[l.dz_at + r * l.n_pad + j]);
        }
    }
    return sum;
}
