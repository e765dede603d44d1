enable f16;

// f32 rows (rows × cols: element (i, j) at offset + i · stride + j · col_stride) as f16 rows
// padded with zeros to k_pad columns, up to `padded` rows (the rows past `rows` get zeros): the
// input of a half-precision dense layer (`half_layer`), whose workgroups also read the padding
// rows, and in a mixed-precision training step the loss's gradient. nprt's own dispatches pass
// offset 0 and column stride 1; the two stay in the uniform that export version 3 documents.

struct HalfRows {
    rows: u32,
    padded: u32,
    cols: u32,
    stride: u32,
    k_pad: u32,
    offset: u32,
    col_stride: u32,
    _pad: u32,
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
        v = src[p.offset + i * p.stride + j * p.col_stride];
    }
    // Saturated: a gradient past f16's range would otherwise become infinite.
    dst[e] = f16(clamp(v, -65504.0, 65504.0));
}
