// `half_weight_sums`' product on tensor cores: 16 × 16 × 16 f16 products into f32 (cooperative
// matrices). Four subgroups of 32 each compute 64 rows × 64 columns of one chunk's sums (4 × 4
// tiles, as `half_dense_coop`), read straight from storage: xᵀ's tiles through column-major
// loads of x as stored (`coopLoad`), dz's row-major (`coopLoadT`). A workgroup covers 256 rows
// × 64 columns of layer `workgroup_id.y`'s gradient for chunk `workgroup_id.z`, the layer's
// column blocks first along `workgroup_id.x` (as many as the layer with the most needs; the
// others' spare workgroups return at once); tiles past x's or dz's padded columns read the
// last tile again and are not written (`finish` keeps to m × n). A tile leaves through
// `coop_drain`. With a bias, one more row of the layer's blocks (past k_pad's) sums dz's
// columns instead, two threads a column over half the chunk's rows each, and with view sums a
// row more per view.

@compute @workgroup_size(128)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    let sg = t / 32u;
    let lane = t % 32u;
    chunk_of = group.z;
    l = layer_at(group.y, group.x);
    // The layer's shape read here rather than from l, which naga's uniformity analysis cannot
    // follow through a private variable.
    let shape = p.shape[group.y];
    let blocks_n = (shape.w + 63u) / 64u;
    let block_i = group.x / blocks_n;
    let block_j = group.x % blocks_n;
    let blocks_k = (shape.z + 255u) / 256u;
    let work = p.work[group.y];
    if (block_i >= blocks_k + work.y + work.z) {
        return;
    }
    if (block_i >= blocks_k) {
        let i = l.m + block_i - blocks_k;
        let j = block_j * 64u + t % 64u;
        let r0 = group.z * p.chunk;
        let r1 = min(p.rows, r0 + p.chunk);
        let mid = r0 + (r1 - r0) / 2u;
        var sum = 0.0;
        if (j < l.n) {
            if (t < 64u) {
                sum = dz_sum(i, j, r0, mid);
            } else {
                sum = dz_sum(i, j, mid, r1);
            }
        }
        staged[t] = sum;
        workgroupBarrier();
        if (t < 64u) {
            finish(i, j, staged[t] + staged[t + 64u]);
        }
        return;
    }
    let row0 = block_i * 256u + sg * 64u;
    let col0 = block_j * 64u;
    let i_last = shape.z - 16u;
    let j_last = shape.w - 16u;
    let i0 = min(row0, i_last);
    let i1 = min(row0 + 16u, i_last);
    let i2 = min(row0 + 32u, i_last);
    let i3 = min(row0 + 48u, i_last);
    let j0 = min(col0, j_last);
    let j1 = min(col0 + 16u, j_last);
    let j2 = min(col0 + 32u, j_last);
    let j3 = min(col0 + 48u, j_last);
    var c00 = coop_mat16x16<f32, C>();
    var c01 = coop_mat16x16<f32, C>();
    var c02 = coop_mat16x16<f32, C>();
    var c03 = coop_mat16x16<f32, C>();
    var c10 = coop_mat16x16<f32, C>();
    var c11 = coop_mat16x16<f32, C>();
    var c12 = coop_mat16x16<f32, C>();
    var c13 = coop_mat16x16<f32, C>();
    var c20 = coop_mat16x16<f32, C>();
    var c21 = coop_mat16x16<f32, C>();
    var c22 = coop_mat16x16<f32, C>();
    var c23 = coop_mat16x16<f32, C>();
    var c30 = coop_mat16x16<f32, C>();
    var c31 = coop_mat16x16<f32, C>();
    var c32 = coop_mat16x16<f32, C>();
    var c33 = coop_mat16x16<f32, C>();
    let r0 = group.z * p.chunk;
    let r1 = min(p.rows, r0 + p.chunk);
    for (var r = r0; r < r1; r += 16u) {
        let xr = l.x_at + r * l.k_pad;
        let x0 = xr + i0;
        let a0 = coopLoad<coop_mat16x16<f16, A>>(&x[x0], l.k_pad);
        let x1 = xr + i1;
        let a1 = coopLoad<coop_mat16x16<f16, A>>(&x[x1], l.k_pad);
        let x2 = xr + i2;
        let a2 = coopLoad<coop_mat16x16<f16, A>>(&x[x2], l.k_pad);
        let x3 = xr + i3;
        let a3 = coopLoad<coop_mat16x16<f16, A>>(&x[x3], l.k_pad);
        let dr = l.dz_at + r * l.n_pad;
        let d0 = dr + j0;
        let b0 = coopLoadT<coop_mat16x16<f16, B>>(&dz[d0], l.n_pad);
        let d1 = dr + j1;
        let b1 = coopLoadT<coop_mat16x16<f16, B>>(&dz[d1], l.n_pad);
        let d2 = dr + j2;
        let b2 = coopLoadT<coop_mat16x16<f16, B>>(&dz[d2], l.n_pad);
        let d3 = dr + j3;
        let b3 = coopLoadT<coop_mat16x16<f16, B>>(&dz[d3], l.n_pad);
        c00 = coopMultiplyAdd(a0, b0, c00);
        c01 = coopMultiplyAdd(a0, b1, c01);
        c02 = coopMultiplyAdd(a0, b2, c02);
        c03 = coopMultiplyAdd(a0, b3, c03);
        c10 = coopMultiplyAdd(a1, b0, c10);
        c11 = coopMultiplyAdd(a1, b1, c11);
        c12 = coopMultiplyAdd(a1, b2, c12);
        c13 = coopMultiplyAdd(a1, b3, c13);
        c20 = coopMultiplyAdd(a2, b0, c20);
        c21 = coopMultiplyAdd(a2, b1, c21);
        c22 = coopMultiplyAdd(a2, b2, c22);
        c23 = coopMultiplyAdd(a2, b3, c23);
        c30 = coopMultiplyAdd(a3, b0, c30);
        c31 = coopMultiplyAdd(a3, b1, c31);
        c32 = coopMultiplyAdd(a3, b2, c32);
        c33 = coopMultiplyAdd(a3, b3, c33);
    }
    drain(c00, sg, lane, row0 + 0u, col0 + 0u);
    drain(c01, sg, lane, row0 + 0u, col0 + 16u);
    drain(c02, sg, lane, row0 + 0u, col0 + 32u);
    drain(c03, sg, lane, row0 + 0u, col0 + 48u);
    drain(c10, sg, lane, row0 + 16u, col0 + 0u);
    drain(c11, sg, lane, row0 + 16u, col0 + 16u);
    drain(c12, sg, lane, row0 + 16u, col0 + 32u);
    drain(c13, sg, lane, row0 + 16u, col0 + 48u);
    drain(c20, sg, lane, row0 + 32u, col0 + 0u);
    drain(c21, sg, lane, row0 + 32u, col0 + 16u);
    drain(c22, sg, lane, row0 + 32u, col0 + 32u);
    drain(c23, sg, lane, row0 + 32u, col0 + 48u);
    drain(c30, sg, lane, row0 + 48u, col0 + 0u);
    drain(c31, sg, lane, row0 + 48u, col0 + 16u);
    drain(c32, sg, lane, row0 + 48u, col0 + 32u);
    drain(c33, sg, lane, row0 + 48u, col0 + 48u);
}
