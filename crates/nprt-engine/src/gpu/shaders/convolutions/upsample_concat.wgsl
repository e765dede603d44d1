// A U-Net decoder level's input: `x` (views × c_x × h × w) up-sampled ×2 by nearest neighbour,
// then the level's skip (views × c_skip × 2h × 2w), channel-major: views × (c_x + c_skip) ×
// 2h × 2w, as the CPU engine joins them.

@group(0) @binding(0) var<uniform> p: Upsample;
@group(0) @binding(1) var<storage, read> x: array<f32>;
@group(0) @binding(2) var<storage, read> skip: array<f32>;
@group(0) @binding(3) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    let channels = p.c_x + p.c_skip;
    let w2 = 2u * p.w;
    let hw2 = 4u * p.h * p.w;
    if (i >= p.views * channels * hw2) {
        return;
    }
    let view = i / (channels * hw2);
    let c = (i / hw2) % channels;
    let y = (i / w2) % (2u * p.h);
    let xo = i % w2;
    if (c < p.c_x) {
        out[i] = x[((view * p.c_x + c) * p.h + y / 2u) * p.w + xo / 2u];
    } else {
        out[i] = skip[(view * p.c_skip + c - p.c_x) * hw2 + y * w2 + xo];
    }
}
