// `half_weight_sums`' product without tensor cores: a thread per sum. It serves adapters without
// cooperative matrices (the tests' software Vulkan), not speed.

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = id.x + id.y * groups.x * 64u;
    let block = (p.m + p.bias) * p.n;
    chunk_of = e / block;
    let r0 = chunk_of * p.chunk;
    if (r0 >= p.rows) {
        return;
    }
    let i = (e % block) / p.n;
    let j = e % p.n;
    let r1 = min(p.rows, r0 + p.chunk);
    if (i == p.m) {
        finish(i, j, dz_sum(j, r0, r1));
        return;
    }
    var sum = 0.0;
    for (var r = r0; r < r1; r++) {
        sum += f32(x[r * p.k_pad + i]) * f32(dz[r * p.n_pad + j]);
    }
    finish(i, j, sum);
}
