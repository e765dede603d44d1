// The gradients of a k × k convolution, per chunk of image rows: per weight (c, ci, ky, kx)
// the sum over the chunk's rows of dz[c] times the input tap it multiplied, and per channel c
// the sum of dz[c] (its bias). The rows of all views are cut into `chunks` chunks of
// `chunk_rows` rows (view-major), one thread per value and chunk, each adding in a fixed
// order; a column sum then adds the chunks in order, the weights' and the biases' in one pass
// (they sit in one block per chunk, laid out as the parameters, where the other convolutions
// of an encoder put theirs too). One thread per value over every row left a few hundred
// threads each walking a whole batch of maps: most of a step's time on a GPU.

struct WeightBackward {
    c_in: u32,
    c_out: u32,
    h: u32,
    w: u32,
    views: u32,
    k: u32,
    chunk_rows: u32,
    chunks: u32,
    // A chunk's block of sums, and where the weights' and the biases' start in it.
    stride: u32,
    w_at: u32,
    b_at: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> p: WeightBackward;
@group(0) @binding(1) var<storage, read> input: array<f32>;
@group(0) @binding(2) var<storage, read> dz: array<f32>;
// Per chunk, the weights' sums (c_out × c_in · k²) and the biases' (c_out).
@group(0) @binding(3) var<storage, read_write> sums: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let o = id.x + id.y * groups.x * 64u;
    let kk = p.k * p.k;
    let taps = p.c_in * kk;
    let per_chunk = p.c_out * (taps + 1u);
    if (o >= p.chunks * per_chunk) {
        return;
    }
    let chunk = o / per_chunk;
    let i = o % per_chunk;
    let c = i / (taps + 1u);
    let j = i % (taps + 1u);
    let hw = p.h * p.w;
    let first = chunk * p.chunk_rows;
    let end = min(p.views * p.h, first + p.chunk_rows);
    var s = 0.0;
    if (j == taps) {
        for (var r = first; r < end; r++) {
            let d = ((r / p.h) * p.c_out + c) * hw + (r % p.h) * p.w;
            for (var x = 0u; x < p.w; x++) {
                s += dz[d + x];
            }
        }
        sums[chunk * p.stride + p.b_at + c] = s;
        return;
    }
    let ci = j / kk;
    let half = i32(p.k / 2u);
    let ky = i32(j % kk / p.k) - half;
    let kx = i32(j % p.k) - half;
    for (var r = first; r < end; r++) {
        let view = r / p.h;
        let y = r % p.h;
        let sy = i32(y) + ky;
        if (sy < 0 || sy >= i32(p.h)) {
            continue;
        }
        let d = (view * p.c_out + c) * hw + y * p.w;
        let src = (view * p.c_in + ci) * hw + u32(sy) * p.w;
        for (var x = 0u; x < p.w; x++) {
            let sx = i32(x) + kx;
            if (sx < 0 || sx >= i32(p.w)) {
                continue;
            }
            s += dz[d + x] * input[src + u32(sx)];
        }
    }
    sums[chunk * p.stride + p.w_at + c * taps + j] = s;
}
