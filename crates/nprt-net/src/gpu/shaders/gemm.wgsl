// C = op(A)·op(B) with an epilogue, the training step's one matrix product. A's element (i, k)
// is a[a_off + i·a_rs + k·a_cs] and B's (k, j) is b[b_off + k·b_rs + j·b_cs], so a transposed
// operand is only other strides: forward y = x·W, backward dx = dz·Wᵀ and dW = xᵀ·dz. C is
// m × n with row stride c_rs, from c_off. The epilogue adds a bias (none, per column, or per
// row group: bias[group[i]·n + j], the light code's share of a shading network's first layer,
// one per view), applies linear/ReLU/SIREN, keeps the pre-activation in z (from 0) where
// backward needs it, and writes or adds to C.
//
// A 16 × 16 workgroup computes a 64 × 64 tile of C, each thread 4 × 4 values strided by 16,
// from 16-deep slices of A and B staged in 8 KiB of workgroup memory.

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
    // 0: linear, 1: ReLU, 2: SIREN, sin(30 v).
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
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> p: Gemm;
@group(0) @binding(1) var<storage, read> a: array<f32>;
@group(0) @binding(2) var<storage, read> b: array<f32>;
@group(0) @binding(3) var<storage, read> bias: array<f32>;
@group(0) @binding(4) var<storage, read> group_of: array<u32>;
@group(0) @binding(5) var<storage, read_write> c: array<f32>;
@group(0) @binding(6) var<storage, read_write> z: array<f32>;

const TILE: u32 = 64u;
const DEPTH: u32 = 16u;
const OMEGA_0: f32 = 30.0;

var<workgroup> as_: array<f32, 1024>;
var<workgroup> bs: array<vec4<f32>, 256>;

fn b_at(k: u32, j: u32, k_end: u32) -> f32 {
    if (k < k_end && j < p.n) {
        return b[p.b_off + k * p.b_rs + j * p.b_cs];
    }
    return 0.0;
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
    var a0 = vec4<f32>(0.0);
    var a1 = vec4<f32>(0.0);
    var a2 = vec4<f32>(0.0);
    var a3 = vec4<f32>(0.0);
    let k_begin = group.z * p.k_chunk;
    let k_end = select(p.k, min(p.k, k_begin + p.k_chunk), p.k_chunk > 0u);
    for (var k0 = k_begin; k0 < k_end; k0 += DEPTH) {
        for (var t = 0u; t < 4u; t++) {
            let e = thread + t * 256u;
            let i = row0 + e / DEPTH;
            let k = k0 + e % DEPTH;
            var v = 0.0;
            if (i < p.m && k < k_end) {
                v = a[p.a_off + i * p.a_rs + k * p.a_cs];
            }
            as_[e] = v;
        }
        let kb = k0 + thread / 16u;
        let j = col0 + 4u * (thread % 16u);
        bs[thread] = vec4<f32>(
            b_at(kb, j, k_end),
            b_at(kb, j + 1u, k_end),
            b_at(kb, j + 2u, k_end),
            b_at(kb, j + 3u, k_end)
        );
        workgroupBarrier();
        for (var k = 0u; k < DEPTH; k++) {
            let bk = bs[k * 16u + local.x];
            a0 += as_[local.y * DEPTH + k] * bk;
            a1 += as_[(local.y + 16u) * DEPTH + k] * bk;
            a2 += as_[(local.y + 32u) * DEPTH + k] * bk;
            a3 += as_[(local.y + 48u) * DEPTH + k] * bk;
        }
        workgroupBarrier();
    }
    let j = col0 + 4u * local.x;
    store(row0 + local.y, j, a0, group.z);
    store(row0 + local.y + 16u, j, a1, group.z);
    store(row0 + local.y + 32u, j, a2, group.z);
    store(row0 + local.y + 48u, j, a3, group.z);
}
