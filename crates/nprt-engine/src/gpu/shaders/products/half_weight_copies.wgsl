enable f16;

// An MLP's f16 copies of its layers' weight rows in a mixed-precision training step, every
// layer's and both kinds in one dispatch after Adam: as stored (k × n from src[offset + i · n
// + j], rows padded with zeros to n_pad values, k + 16 rows: the forward product's right
// operand) and transposed (n × k, rows of k_pad values, n + 16 rows: the input gradient's).
// One thread per f16 value of either copy, a layer's stored copy's first, the layers' one
// after another; values saturate at f16's largest, as `half_rows`' do.

struct Copies {
    layers: u32,
    // Threads the layers take in all.
    threads: u32,
    _pad0: u32,
    _pad1: u32,
    // Per layer: its copies' rows k and columns n, and their padded widths.
    shape: array<vec4<u32>, 8>,
    // Per layer: where its rows start in src, where its copies start in their buffers (an
    // MLP's layers share one of each), and its first thread.
    at: array<vec4<u32>, 8>,
}

@group(0) @binding(0) var<uniform> p: Copies;
@group(0) @binding(1) var<storage, read> src: array<f32>;
@group(0) @binding(2) var<storage, read_write> stored: array<f16>;
@group(0) @binding(3) var<storage, read_write> transposed: array<f16>;

// W's element (i, j) of a layer of shape s from offset, zero outside k × n.
fn weight(s: vec4<u32>, offset: u32, i: u32, j: u32) -> f16 {
    var v = 0.0;
    if (i < s.x && j < s.y) {
        v = src[offset + i * s.y + j];
    }
    return f16(clamp(v, -65504.0, 65504.0));
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = id.x + id.y * groups.x * 64u;
    if (e >= p.threads) {
        return;
    }
    var i = 0u;
    while (i + 1u < p.layers && e >= p.at[i + 1u].w) {
        i++;
    }
    let s = p.shape[i];
    let a = p.at[i];
    let v = e - a.w;
    let first = (s.x + 16u) * s.w;
    if (v < first) {
        stored[a.y + v] = weight(s, a.x, v / s.w, v % s.w);
        return;
    }
    let t = v - first;
    transposed[a.z + t] = weight(s, a.x, t % s.z, t / s.z);
}
