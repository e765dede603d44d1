// `half_dense_coop`'s product without tensor cores (under the same epilogues): a thread per column of the workgroup's tile,
// down its 256 rows. It serves adapters without cooperative matrices (Mesa's software Vulkan,
// where the tests check the half-precision layout and epilogue), not speed.

@compute @workgroup_size(64)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    let j = group.x * COLS + t;
    if (j >= p.n_pad) {
        return;
    }
    for (var r = 0u; r < ROWS; r++) {
        let i = group.y * ROWS + r;
        var sum = 0.0;
        for (var k = 0u; k < p.k_pad; k++) {
            sum += f32(x[i * p.k_pad + k]) * f32(w[p.w_off + k * p.n_pad + j]);
        }
        finish(i, j, sum);
    }
}
