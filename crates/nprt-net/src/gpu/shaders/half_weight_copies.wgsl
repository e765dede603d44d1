enable f16;

// A dense layer's f16 copies of its weight rows in a mixed-precision training step, both in
// one dispatch after Adam: as stored (k × n from src[offset + i · n + j], rows padded with zeros
// to n_pad values, k + 16 rows: the forward product's right operand) and transposed (n × k,
// rows of k_pad values, n + 16 rows: the input gradient's). One thread per f16 value of either
// copy, the stored copy's first; values saturate at f16's largest, as `half_rows`' do.

struct Copies {
    k: u32,
    n: u32,
    offset: u32,
    n_pad: u32,
    k_pad: u32,
    // Where each copy starts in its buffer (an MLP's layers share one of each).
    stored_off: u32,
    transposed_off: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> p: Copies;
@group(0) @binding(1) var<storage, read> src: array<f32>;
@group(0) @binding(2) var<storage, read_write> stored: array<f16>;
@group(0) @binding(3) var<storage, read_write> transposed: array<f16>;

// W's element (i, j), zero outside k × n.
fn weight(i: u32, j: u32) -> f16 {
    var v = 0.0;
    if (i < p.k && j < p.n) {
        v = src[p.offset + i * p.n + j];
    }
    return f16(clamp(v, -65504.0, 65504.0));
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = id.x + id.y * groups.x * 64u;
    let first = (p.k + 16u) * p.n_pad;
    if (e < first) {
        stored[p.stored_off + e] = weight(e / p.n_pad, e % p.n_pad);
        return;
    }
    let t = e - first;
    if (t < (p.n + 16u) * p.k_pad) {
        transposed[p.transposed_off + t] = weight(t % p.k_pad, t / p.k_pad);
    }
}
