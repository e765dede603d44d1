// The light code's share of a shading network's first layer, once per lighting: b' = b + ê·W_ê,
// where W_ê are the weight rows from code_row that multiply ê. Every pixel under that lighting
// then needs only its own inputs' rows (dense.wgsl with b' as its bias).

struct CodeBias {
    d_out: u32,
    code_row: u32,
    code_size: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> p: CodeBias;
@group(0) @binding(1) var<storage, read> code: array<f32>;
@group(0) @binding(2) var<storage, read> w: array<f32>;
@group(0) @binding(3) var<storage, read> b: array<f32>;
@group(0) @binding(4) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let o = id.x + id.y * groups.x * 64u;
    if (o >= p.d_out) {
        return;
    }
    var s = 0.0;
    for (var k = 0u; k < p.code_size; k++) {
        s += code[k] * w[(p.code_row + k) * p.d_out + o];
    }
    out[o] = b[o] + s;
}
