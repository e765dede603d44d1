// `half_weight_sums`' product without tensor cores, for adapters without cooperative matrices
// (the tests' software Vulkan): a thread per 4 × 4 sums of a chunk, so that each value it loads
// serves four products (a thread a sum loaded two values a product). The bias's row reads x as
// ones, a view's row as ones on that view's rows and zeros elsewhere: dz's column sums, in the
// same order as `dz_sum`. A chunk's threads run every layer's
// sums, the layers' one after another (`work`).

// x's value in row r (starting at xr), column i: past the weight's rows, ones where the sum
// row counts row r (`counts`), zeros past the last.
fn x_at(r: u32, xr: u32, i: u32) -> f32 {
    if (i < l.m) {
        return f32(x[xr + i]);
    }
    return select(0.0, 1.0, i < l.m + l.bias + l.views && counts(r, i));
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = id.x + id.y * groups.x * 64u;
    // Threads a chunk takes: every layer's 4 × 4 blocks (the last entry of work ends them).
    let per_chunk = p.work[p.layers].x;
    chunk_of = e / per_chunk;
    let r0 = chunk_of * p.chunk;
    if (r0 >= p.rows) {
        return;
    }
    l = layer_of(e % per_chunk);
    let blocks_n = (l.n + 3u) / 4u;
    let i0 = 4u * (l.item / blocks_n);
    let j0 = 4u * (l.item % blocks_n);
    let r1 = min(p.rows, r0 + p.chunk);
    // Row i0 + c of the sums in sums[c], columns j0..j0 + 3 (within n_pad, a multiple of 16).
    var sums: array<vec4<f32>, 4>;
    for (var r = r0; r < r1; r++) {
        let xr = l.x_at + r * l.k_pad;
        let d = l.dz_at + r * l.n_pad + j0;
        let b = vec4(f32(dz[d]), f32(dz[d + 1u]), f32(dz[d + 2u]), f32(dz[d + 3u]));
        sums[0] += x_at(r, xr, i0) * b;
        sums[1] += x_at(r, xr, i0 + 1u) * b;
        sums[2] += x_at(r, xr, i0 + 2u) * b;
        sums[3] += x_at(r, xr, i0 + 3u) * b;
    }
    for (var c = 0u; c < 4u; c++) {
        for (var q = 0u; q < 4u; q++) {
            finish(i0 + c, j0 + q, sums[c][q]);
        }
    }
}
