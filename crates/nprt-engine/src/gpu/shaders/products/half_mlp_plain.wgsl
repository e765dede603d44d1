// `half_mlp_coop`'s MLP without tensor cores (under the same epilogue), for adapters without
// cooperative matrices (Mesa's software Vulkan, where the tests check the fused pass against
// the CPU engine). Thread t sums 8 rows (8 · (t / 16) on) × the columns t % 16 + 16 q of the
// layer, so that each input value and weight it loads serves 16 and 8 products (a thread a row
// and column loaded two values a product); its sums are held until every thread has read the
// layer's input.

@compute @workgroup_size(128)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    row0 = group.x * MLP_ROWS;
    stage_input(t);
    let r0 = 8u * (t / 16u);
    let lane = t % 16u;
    for (var l = 0u; l < p.layers; l++) {
        workgroupBarrier();
        layer = l;
        let s = p.shape[l];
        let tiles = s.z / 16u;
        // Rows r0..r0 + 3 and r0 + 4..r0 + 7 of column lane + 16 q: sums[2 q] and [2 q + 1].
        var sums: array<vec4<f32>, 32>;
        // One term a k iteration and the tiles innermost: llvmpipe ends a loop past 65,535
        // iterations of one invocation, which a loop over rows inside would reach.
        for (var k = 0u; k < s.x; k++) {
            let a = r0 * ACT + k;
            let lo = vec4(f32(act[a]), f32(act[a + ACT]), f32(act[a + 2u * ACT]), f32(act[a + 3u * ACT]));
            let b = a + 4u * ACT;
            let hi = vec4(f32(act[b]), f32(act[b + ACT]), f32(act[b + 2u * ACT]), f32(act[b + 3u * ACT]));
            let row = p.at[l].x + k * s.z + lane;
            for (var q = 0u; q < tiles; q++) {
                let wv = f32(w[row + 16u * q]);
                sums[2u * q] += lo * wv;
                sums[2u * q + 1u] += hi * wv;
            }
        }
        workgroupBarrier();
        for (var q = 0u; q < tiles; q++) {
            let j = lane + 16u * q;
            for (var r = 0u; r < 4u; r++) {
                finish(r0 + r, j, sums[2u * q][r]);
                finish(r0 + 4u + r, j, sums[2u * q + 1u][r]);
            }
        }
    }
}
