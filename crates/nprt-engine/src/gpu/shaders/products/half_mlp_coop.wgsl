// `half_mlp`'s product on tensor cores: 16 × 16 × 16 f16 products into f32 (cooperative
// matrices), the layer's input read from workgroup memory and its weight straight from storage.
// Four subgroups of 32 share each layer: subgroup s computes the workgroup's 64 rows × the
// column tiles s, s + 4, s + 8 and s + 12 (of up to 16, a layer 256 wide), every tile of W
// loaded used four times, as in `half_dense_coop`. Cooperative matrices need control flow
// uniform over the workgroup, so a layer takes as many passes of four tiles as its columns
// need, the same for every subgroup: a subgroup's tile past the columns reads the last tile
// again and is not written (at most three tiles of a pass). The layer's output replaces its
// input in `act` once every subgroup has read it, each tile through `coop_drain`.

// A layer's passes, shared through workgroup memory: naga takes a value read from a uniform
// array at the loop's index as non-uniform, and `workgroupUniformLoad` makes it uniform.
var<workgroup> passes_of: u32;

@compute @workgroup_size(128)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    let sg = t / 32u;
    let lane = t % 32u;
    row0 = group.x * MLP_ROWS;
    stage_input(t);
    for (var l = 0u; l < p.layers; l++) {
        workgroupBarrier();
        layer = l;
        let s = p.shape[l];
        let ldw = s.z;
        if (t == 0u) {
            passes_of = (s.z / 16u + 3u) / 4u;
        }
        let passes = workgroupUniformLoad(&passes_of);
        let last = s.z - 16u;
        let col0 = sg * 16u;
        let col1 = sg * 16u + 64u;
        let col2 = sg * 16u + 128u;
        let col3 = sg * 16u + 192u;
        let at0 = min(col0, last);
        let at1 = min(col1, last);
        let at2 = min(col2, last);
        let at3 = min(col3, last);
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
        for (var k = 0u; k < s.x; k += 16u) {
            let a0 = coopLoadT<coop_mat16x16<f16, A>>(&act[k], ACT);
            let a1 = coopLoadT<coop_mat16x16<f16, A>>(&act[16u * ACT + k], ACT);
            let a2 = coopLoadT<coop_mat16x16<f16, A>>(&act[32u * ACT + k], ACT);
            let a3 = coopLoadT<coop_mat16x16<f16, A>>(&act[48u * ACT + k], ACT);
            let wk = p.at[l].x + k * ldw;
            if (passes > 0u) {
                let b = coopLoadT<coop_mat16x16<f16, B>>(&w[wk + at0], ldw);
                c00 = coopMultiplyAdd(a0, b, c00);
                c10 = coopMultiplyAdd(a1, b, c10);
                c20 = coopMultiplyAdd(a2, b, c20);
                c30 = coopMultiplyAdd(a3, b, c30);
            }
            if (passes > 1u) {
                let b = coopLoadT<coop_mat16x16<f16, B>>(&w[wk + at1], ldw);
                c01 = coopMultiplyAdd(a0, b, c01);
                c11 = coopMultiplyAdd(a1, b, c11);
                c21 = coopMultiplyAdd(a2, b, c21);
                c31 = coopMultiplyAdd(a3, b, c31);
            }
            if (passes > 2u) {
                let b = coopLoadT<coop_mat16x16<f16, B>>(&w[wk + at2], ldw);
                c02 = coopMultiplyAdd(a0, b, c02);
                c12 = coopMultiplyAdd(a1, b, c12);
                c22 = coopMultiplyAdd(a2, b, c22);
                c32 = coopMultiplyAdd(a3, b, c32);
            }
            if (passes > 3u) {
                let b = coopLoadT<coop_mat16x16<f16, B>>(&w[wk + at3], ldw);
                c03 = coopMultiplyAdd(a0, b, c03);
                c13 = coopMultiplyAdd(a1, b, c13);
                c23 = coopMultiplyAdd(a2, b, c23);
                c33 = coopMultiplyAdd(a3, b, c33);
            }
        }
        workgroupBarrier();
        drain(c00, sg, lane, 0u, col0);
        drain(c01, sg, lane, 0u, col1);
        drain(c02, sg, lane, 0u, col2);
        drain(c03, sg, lane, 0u, col3);
        drain(c10, sg, lane, 16u, col0);
        drain(c11, sg, lane, 16u, col1);
        drain(c12, sg, lane, 16u, col2);
        drain(c13, sg, lane, 16u, col3);
        drain(c20, sg, lane, 32u, col0);
        drain(c21, sg, lane, 32u, col1);
        drain(c22, sg, lane, 32u, col2);
        drain(c23, sg, lane, 32u, col3);
        drain(c30, sg, lane, 48u, col0);
        drain(c31, sg, lane, 48u, col1);
        drain(c32, sg, lane, 48u, col2);
        drain(c33, sg, lane, 48u, col3);
    }
}
