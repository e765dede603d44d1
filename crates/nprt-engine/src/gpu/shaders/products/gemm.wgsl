// C = op(A)·op(B) with an epilogue, the training step's one matrix product. A's element (i, k)
// is a[a_off + i·a_rs + k·a_cs] and B's (k, j) is b[b_off + k·b_rs + j·b_cs], so a transposed
// operand is only other strides: forward y = x·W, backward dx = dz·Wᵀ and dW = xᵀ·dz. C is
// m × n with row stride c_rs, from c_off. The epilogue adds a bias (none, per column, or per
// row group: bias[group[i]·n + j], the light code's share of a shading network's first layer,
// one per view), applies linear/ReLU/SIREN, keeps the pre-activation in z (from 0) where
// backward needs it, and writes or adds to C. Backward, it instead multiplies by ReLU's or
// SIREN's derivative at the pre-activation z holds: dx = (dz·Wᵀ) ⊙ f'(z) in one pass.
//
// A 16 × 16 workgroup computes a 128 × 128 tile of C, each thread 8 × 8 values (rows 4·ty..
// and 64 + 4·ty.., columns 4·tx.. and 64 + 4·tx..), from 8-deep slices of A and B staged in
// workgroup memory as vec4s along the tile (k-major, rows padded by one vec4): per k a thread
// reads two vec4s of A and two of B for 64 multiply-adds, where a 4 × 4 block per thread read
// five values for 16 and was bound by workgroup-memory reads.

struct Gemm {
    m: u32,
    n: u32,
    k: u32,
    a_off: u32,
    a_rs: u32,
    a_cs: u32,
    b_off: u32,
    b_rs: u32,
    b_cs: u32,
    c_rs: u32,
    // 0: none, 1: bias[j], 2: bias[group[i] · n + j].
    bias: u32,
    // 0: linear, 1: ReLU, 2: SIREN, sin(30 v); 3: v · (z > 0), 4: v · 30 cos(30 z).
    activation: u32,
    // 1: C += result instead of C = result.
    accumulate: u32,
    // 1: also write the pre-activation to z (same layout as C).
    keep_z: u32,
    // Where the bias starts in its buffer, and C in its.
    bias_off: u32,
    c_off: u32,
    // Split over k (0: none): workgroup layer z sums k from z · k_chunk, k_chunk of them, into
    // its own copy of C at c_off + z · c_chunk, which a column sum then adds in order.
    k_chunk: u32,
    c_chunk: u32,
    // 1 + a row of A that reads as ones (0: none): a weight gradient's product then also sums
    // its bias's gradient, Σ over rows of dz, on that row of C.
    ones_row: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> p: Gemm;
@group(0) @binding(1) var<storage, read> a: array<f32>;
@group(0) @binding(2) var<storage, read> b: array<f32>;
@group(0) @binding(3) var<storage, read> bias: array<f32>;
@group(0) @binding(4) var<storage, read> group_of: array<u32>;
@group(0) @binding(5) var<storage, read_write> c: array<f32>;
@group(0) @binding(6) var<storage, read_write> z: array<f32>;

const TILE: u32 = 128u;
const DEPTH: u32 = 8u;
// vec4s per staged k row: 32 and one of padding.
const ROW: u32 = 33u;
const OMEGA_0: f32 = 30.0;

var<workgroup> as_: array<vec4<f32>, 264>;
var<workgroup> bs: array<vec4<f32>, 264>;

// A's element (i, k) within the product (ones on `ones_row`), zero outside it.
fn a_at(i: u32, k: u32, k_end: u32) -> f32 {
    if (i >= p.m || k >= k_end) {
        return 0.0;
    }
    if (i + 1u == p.ones_row) {
        return 1.0;
    }
    return a[p.a_off + i * p.a_rs + k * p.a_cs];
}

// B's element (k, j) within the product, zero outside it.
fn b_at(k: u32, j: u32, k_end: u32) -> f32 {
    if (k >= k_end || j >= p.n) {
        return 0.0;
    }
    return b[p.b_off + k * p.b_rs + j * p.b_cs];
}

fn store(i: u32, j0: u32, acc: vec4<f32>, layer: u32) {
    if (i >= p.m) {
        return;
    }
    for (var t = 0u; t < 4u; t++) {
        let j = j0 + t;
        if (j >= p.n) {
            return;
        }
        var v = acc[t];
        if (p.bias == 1u) {
            v += bias[p.bias_off + j];
        } else if (p.bias == 2u) {
            v += bias[p.bias_off + group_of[i] * p.n + j];
        }
        if (p.keep_z == 1u) {
            z[i * p.c_rs + j] = v;
        }
        if (p.activation == 1u) {
            v = max(v, 0.0);
        } else if (p.activation == 2u) {
            v = sin(OMEGA_0 * v);
        } else if (p.activation == 3u) {
            v = select(0.0, v, z[i * p.c_rs + j] > 0.0);
        } else if (p.activation == 4u) {
            v *= OMEGA_0 * cos(OMEGA_0 * z[i * p.c_rs + j]);
        }
        let o = p.c_off + layer * p.c_chunk + i * p.c_rs + j;
        if (p.accumulate == 1u) {
            v += c[o];
        }
        c[o] = v;
    }
}

@compute @workgroup_size(16, 16)
fn main(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) thread: u32,
) {
    let row0 = group.y * TILE;
    let col0 = group.x * TILE;
    let tx = local.x;
    let ty = local.y;
    var c0 = vec4<f32>(0.0);
    var c1 = vec4<f32>(0.0);
    var c2 = vec4<f32>(0.0);
    var c3 = vec4<f32>(0.0);
    var c4 = vec4<f32>(0.0);
    var c5 = vec4<f32>(0.0);
    var c6 = vec4<f32>(0.0);
    var c7 = vec4<f32>(0.0);
    var d0 = vec4<f32>(0.0);
    var d1 = vec4<f32>(0.0);
    var d2 = vec4<f32>(0.0);
    var d3 = vec4<f32>(0.0);
    var d4 = vec4<f32>(0.0);
    var d5 = vec4<f32>(0.0);
    var d6 = vec4<f32>(0.0);
    var d7 = vec4<f32>(0.0);
    let k_begin = group.z * p.k_chunk;
    let k_end = select(p.k, min(p.k, k_begin + p.k_chunk), p.k_chunk > 0u);
    for (var k0 = k_begin; k0 < k_end; k0 += DEPTH) {
        // Each thread stages one vec4 of A (four rows at one k) and one of B (four columns at
        // one k), whole, so that no two threads write parts of one vector; neighbouring threads
        // read neighbouring addresses along whichever stride is 1.
        var kk = thread % DEPTH;
        var i4 = thread / DEPTH;
        if (p.a_rs == 1u) {
            kk = thread / 32u;
            i4 = thread % 32u;
        }
        as_[kk * ROW + i4] = vec4<f32>(
            a_at(row0 + 4u * i4, k0 + kk, k_end),
            a_at(row0 + 4u * i4 + 1u, k0 + kk, k_end),
            a_at(row0 + 4u * i4 + 2u, k0 + kk, k_end),
            a_at(row0 + 4u * i4 + 3u, k0 + kk, k_end),
        );
        var kb = thread / 32u;
        var j4 = thread % 32u;
        if (p.b_cs != 1u) {
            kb = thread % DEPTH;
            j4 = thread / DEPTH;
        }
        bs[kb * ROW + j4] = vec4<f32>(
            b_at(k0 + kb, col0 + 4u * j4, k_end),
            b_at(k0 + kb, col0 + 4u * j4 + 1u, k_end),
            b_at(k0 + kb, col0 + 4u * j4 + 2u, k_end),
            b_at(k0 + kb, col0 + 4u * j4 + 3u, k_end),
        );
        workgroupBarrier();
        for (var k = 0u; k < DEPTH; k++) {
            let a_lo = as_[k * ROW + ty];
            let a_hi = as_[k * ROW + 16u + ty];
            let b_lo = bs[k * ROW + tx];
            let b_hi = bs[k * ROW + 16u + tx];
            c0 += a_lo.x * b_lo;
            c1 += a_lo.y * b_lo;
            c2 += a_lo.z * b_lo;
            c3 += a_lo.w * b_lo;
            c4 += a_hi.x * b_lo;
            c5 += a_hi.y * b_lo;
            c6 += a_hi.z * b_lo;
            c7 += a_hi.w * b_lo;
            d0 += a_lo.x * b_hi;
            d1 += a_lo.y * b_hi;
            d2 += a_lo.z * b_hi;
            d3 += a_lo.w * b_hi;
            d4 += a_hi.x * b_hi;
            d5 += a_hi.y * b_hi;
            d6 += a_hi.z * b_hi;
            d7 += a_hi.w * b_hi;
        }
        workgroupBarrier();
    }
    let i_lo = row0 + 4u * ty;
    let i_hi = row0 + 64u + 4u * ty;
    let j_lo = col0 + 4u * tx;
    let j_hi = col0 + 64u + 4u * tx;
    store(i_lo, j_lo, c0, group.z);
    store(i_lo + 1u, j_lo, c1, group.z);
    store(i_lo + 2u, j_lo, c2, group.z);
    store(i_lo + 3u, j_lo, c3, group.z);
    store(i_hi, j_lo, c4, group.z);
    store(i_hi + 1u, j_lo, c5, group.z);
    store(i_hi + 2u, j_lo, c6, group.z);
    store(i_hi + 3u, j_lo, c7, group.z);
    store(i_lo, j_hi, d0, group.z);
    store(i_lo + 1u, j_hi, d1, group.z);
    store(i_lo + 2u, j_hi, d2, group.z);
    store(i_lo + 3u, j_hi, d3, group.z);
    store(i_hi, j_hi, d4, group.z);
    store(i_hi + 1u, j_hi, d5, group.z);
    store(i_hi + 2u, j_hi, d6, group.z);
    store(i_hi + 3u, j_hi, d7, group.z);
}
