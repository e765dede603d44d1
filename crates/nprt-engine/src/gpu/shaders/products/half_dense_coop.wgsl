// A half-precision dense layer's product on tensor cores: 16 × 16 × 16 f16 products into f32
// (cooperative matrices), under the epilogue of `half_layer` (frames) or `half_train_layer`
// (training's forward and input-gradient products). Four subgroups of 32 each compute 64 rows × 64 columns (4 × 4 tiles: every tile of
// x and W loaded is used four times), read straight from storage: on an H200, a probe of this
// shape ran 60-76 TFLOP/s where staging through workgroup memory ran 10-18. A tile leaves
// through `coop_drain`.

@compute @workgroup_size(128)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    let sg = t / 32u;
    let lane = t % 32u;
    let row0 = group.y * ROWS + sg * 64u;
    let col0 = group.x * COLS;
    let lda = p.k_pad;
    let ldw = p.n_pad;
    // Tiles past n_pad (the last column of workgroups) read the last tile again, and are not
    // written: the loads stay in W.
    let last = p.n_pad - 16u;
    let j1 = min(col0 + 16u, last);
    let j2 = min(col0 + 32u, last);
    let j3 = min(col0 + 48u, last);
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
    for (var k = 0u; k < p.k_pad; k += 16u) {
        let xa = row0 * lda + k;
        let a0 = coopLoadT<coop_mat16x16<f16, A>>(&x[xa], lda);
        let xb = xa + 16u * lda;
        let a1 = coopLoadT<coop_mat16x16<f16, A>>(&x[xb], lda);
        let xc = xb + 16u * lda;
        let a2 = coopLoadT<coop_mat16x16<f16, A>>(&x[xc], lda);
        let xd = xc + 16u * lda;
        let a3 = coopLoadT<coop_mat16x16<f16, A>>(&x[xd], lda);
        let wk = p.w_off + k * ldw;
        let w0 = wk + col0;
        let b0 = coopLoadT<coop_mat16x16<f16, B>>(&w[w0], ldw);
        let w1 = wk + j1;
        let b1 = coopLoadT<coop_mat16x16<f16, B>>(&w[w1], ldw);
        let w2 = wk + j2;
        let b2 = coopLoadT<coop_mat16x16<f16, B>>(&w[w2], ldw);
        let w3 = wk + j3;
        let b3 = coopLoadT<coop_mat16x16<f16, B>>(&w[w3], ldw);
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
