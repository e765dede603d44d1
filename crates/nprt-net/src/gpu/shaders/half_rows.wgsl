enable f16;

// f32 rows (rows × cols, row stride `stride`) as f16 rows padded with zeros to k_pad columns:
// the input of a half-precision dense layer (`half_layer`), up to `padded` rows (the rows past
// `rows`, which that layer's workgroups also read, get zeros).

struct HalfRows {
    rows: u32,
    padded: u32,
    cols: u32,
    stride: u32,
    k_pad: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> p: HalfRows;
@group(0) @binding(1) var<storage, read> src: array<f32>;
@group(0) @binding(2) var<storage, read_write> dst: array<f16>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = id.x + id.y * groups.x * 64u;
    if (e >= p.padded * p.k_pad) {
        return;
    }
    let i = e / p.k_pad;
    let j = e % p.k_pad;
    var v = 0.0;
    if (i < p.rows && j < p.cols) {
        v = src[i * p.stride + j];
    }
    dst[e] = f16(v);
}
