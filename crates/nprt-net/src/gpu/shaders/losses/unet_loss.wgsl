// The U-Net's prediction, its masked loss and the loss's gradient at the output convolution:
// per value of views × 3 × h × w, the prediction exp(y) times the map's scale (views × 3), the
// loss element times the pixel's mask (views × h × w) for the sum the host normalises, and the
// gradient at y: the slope times the mask and `norm` (1 / (3 · the batch's foreground pixels)),
// times the prediction (d exp(y) / dy).

struct UnetLoss {
    views: u32,
    hw: u32,
    loss: u32,
    _pad0: u32,
    norm: f32,
    _pad1: f32,
    _pad2: f32,
    _pad3: f32,
}

@group(0) @binding(0) var<uniform> p: UnetLoss;
@group(0) @binding(1) var<storage, read> y: array<f32>;
@group(0) @binding(2) var<storage, read> reference: array<f32>;
@group(0) @binding(3) var<storage, read> mask: array<f32>;
@group(0) @binding(4) var<storage, read> scale: array<f32>;
@group(0) @binding(5) var<storage, read_write> prediction: array<f32>;
@group(0) @binding(6) var<storage, read_write> d_y: array<f32>;
@group(0) @binding(7) var<storage, read_write> value: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the 65,535 one dimension allows.
    let i = id.x + id.y * groups.x * 64u;
    if (i >= p.views * 3u * p.hw) {
        return;
    }
    let plane = i / p.hw;
    let m = mask[(plane / 3u) * p.hw + i % p.hw];
    let q = exp(y[i]) * scale[plane];
    let e = loss_element(p.loss, q, reference[i]);
    prediction[i] = q;
    value[i] = e.x * m;
    d_y[i] = e.y * m * p.norm * q;
}
