// 2 × 2 max-pool with stride 2 over views × c × h × w planes (the U-Net's encoder levels): per
// pooled value the largest of its window, the first of equal maxima in row order, as the CPU
// engine's max_pool, and which of the window's four it took (0-3 in row order) for backward.

struct Pool {
    planes: u32,
    h: u32,
    w: u32,
    _pad0: u32,
}

@group(0) @binding(0) var<uniform> p: Pool;
@group(0) @binding(1) var<storage, read> input: array<f32>;
@group(0) @binding(2) var<storage, read_write> out: array<f32>;
@group(0) @binding(3) var<storage, read_write> taken: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    let ho = p.h / 2u;
    let wo = p.w / 2u;
    if (i >= p.planes * ho * wo) {
        return;
    }
    let plane = i / (ho * wo);
    let oy = (i / wo) % ho;
    let ox = i % wo;
    let base = plane * p.h * p.w + 2u * oy * p.w + 2u * ox;
    var m = input[base];
    var slot = 0u;
    for (var k = 1u; k < 4u; k++) {
        let v = input[base + (k / 2u) * p.w + k % 2u];
        if (v > m) {
            m = v;
            slot = k;
        }
    }
    out[i] = m;
    taken[i] = slot;
}
