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
        // Four terms an iteration: llvmpipe ends a loop past 65,535 iterations of one
        // invocation, which 256 rows of a 256-wide x reach (the last row's sum came out short).
        for (var k = 0u; k < p.k_pad; k += 4u) {
            let a = i * p.k_pad + k;
            let b = p.w_off + k * p.n_pad + j;
            sum += f32(x[a]) * f32(w[b]);
            sum += f32(x[a + 1u]) * f32(w[b + p.n_pad]);
            sum += f32(x[a + 2u]) * f32(w[b + 2u * p.n_pad]);
            sum += f32(x[a + 3u]) * f32(w[b + 3u * p.n_pad]);
        }
        finish(i, j, sum);
    }
}
