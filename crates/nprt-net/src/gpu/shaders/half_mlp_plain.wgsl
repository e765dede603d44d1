// `half_mlp_coop`'s MLP without tensor cores (under the same epilogue): two threads a row, each
// summing every other column of the layer, held until every thread has read the layer's input.
// It serves adapters without cooperative matrices (Mesa's software Vulkan, where the tests
// check the fused pass against the CPU engine), not speed.

@compute @workgroup_size(128)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    row0 = group.x * MLP_ROWS;
    stage_input(t);
    let r = t / 2u;
    let first = t % 2u;
    for (var l = 0u; l < p.layers; l++) {
        workgroupBarrier();
        layer = l;
        let s = p.shape[l];
        var sums: array<f32, 128>;
        for (var q = 0u; first + 2u * q < s.z; q++) {
            let j = first + 2u * q;
            var sum = 0.0;
            // Four terms an iteration: llvmpipe ends a loop past 65,535 iterations of one
            // invocation, which 64 columns of a 256-wide MLP's layers would reach.
            for (var k = 0u; k < s.x; k += 4u) {
                let a = r * ACT + k;
                let b = p.at[l].x + k * s.z + j;
                sum += f32(act[a]) * f32(w[b]);
                sum += f32(act[a + 1u]) * f32(w[b + s.z]);
                sum += f32(act[a + 2u]) * f32(w[b + 2u * s.z]);
                sum += f32(act[a + 3u]) * f32(w[b + 3u * s.z]);
            }
            sums[q] = sum;
        }
        workgroupBarrier();
        for (var q = 0u; first + 2u * q < s.z; q++) {
            finish(r, first + 2u * q, sums[q]);
        }
    }
}
