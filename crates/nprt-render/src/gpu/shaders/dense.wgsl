// One dense layer over a block of rows: y = act(x·W + b). x is rows × d_in (row stride
// x_stride), W is d_in × d_out row-major from element w_offset (burn's Linear layout; a
// shading network's first layer reads only the rows that multiply its per-pixel inputs, the
// light code's rows having gone into b), y is rows × d_out.
//
// A 16 × 16 workgroup computes a 64 × 64 tile of y, each thread 4 × 4 values strided by 16 so
// that neighbouring threads read and write neighbouring columns; 16-deep slices of x and W are
// staged in workgroup memory (8 KiB, within every adapter's limit). Per-thread arrays of the
// layer's full width would not fit in a real GPU's registers.

struct Dense {
    rows: u32,
    d_in: u32,
    d_out: u32,
    // 0: linear, 1: ReLU, 2: SIREN, sin(30 v).
    activation: u32,
    x_stride: u32,
    w_offset: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<uniform> p: Dense;
@group(0) @binding(1) var<storage, read> x: array<f32>;
@group(0) @binding(2) var<storage, read> w: array<f32>;
@group(0) @binding(3) var<storage, read> b: array<f32>;
@group(0) @binding(4) var<storage, read_write> y: array<f32>;

const TILE: u32 = 64u;
const DEPTH: u32 = 16u;
const OMEGA_0: f32 = 30.0;

// x's slice: TILE rows × DEPTH; W's slice: DEPTH rows × TILE columns as 16 vec4s per row.
var<workgroup> xs: array<f32, 1024>;
var<workgroup> ws: array<vec4<f32>, 256>;

fn weight(k: u32, c: u32) -> f32 {
    if (k < p.d_in && c < p.d_out) {
        return w[p.w_offset + k * p.d_out + c];
    }
    return 0.0;
}

fn store(r: u32, c: u32, acc: vec4<f32>) {
    if (r >= p.rows) {
        return;
    }
    for (var j = 0u; j < 4u; j++) {
        if (c + j < p.d_out) {
            var v = acc[j] + b[c + j];
            if (p.activation == 1u) {
                v = max(v, 0.0);
            } else if (p.activation == 2u) {
                v = sin(OMEGA_0 * v);
            }
            y[r * p.d_out + c + j] = v;
        }
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
    // Thread (x, y) computes rows y, y + 16, y + 32, y + 48 and the 4 columns from 4x: four
    // vec4 accumulators, no private array a compiler might keep in memory.
    var a0 = vec4<f32>(0.0);
    var a1 = vec4<f32>(0.0);
    var a2 = vec4<f32>(0.0);
    var a3 = vec4<f32>(0.0);
    for (var k0 = 0u; k0 < p.d_in; k0 += DEPTH) {
        for (var i = 0u; i < 4u; i++) {
            let e = thread + i * 256u;
            let r = row0 + e / DEPTH;
            let kx = k0 + e % DEPTH;
            var xv = 0.0;
            if (r < p.rows && kx < p.d_in) {
                xv = x[r * p.x_stride + kx];
            }
            xs[e] = xv;
        }
        let kw = k0 + thread / 16u;
        let c = col0 + 4u * (thread % 16u);
        ws[thread] = vec4<f32>(weight(kw, c), weight(kw, c + 1u), weight(kw, c + 2u), weight(kw, c + 3u));
        workgroupBarrier();
        for (var k = 0u; k < DEPTH; k++) {
            let wk = ws[k * 16u + local.x];
            a0 += xs[local.y * DEPTH + k] * wk;
            a1 += xs[(local.y + 16u) * DEPTH + k] * wk;
            a2 += xs[(local.y + 32u) * DEPTH + k] * wk;
            a3 += xs[(local.y + 48u) * DEPTH + k] * wk;
        }
        workgroupBarrier();
    }
    let c = col0 + 4u * local.x;
    store(row0 + local.y, c, a0);
    store(row0 + local.y + 16u, c, a1);
    store(row0 + local.y + 32u, c, a2);
    store(row0 + local.y + 48u, c, a3);
}
