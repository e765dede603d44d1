// glam's lerp, in its order of operations (the device's mix may fuse them differently).
fn lerp(a: vec3<f32>, b: vec3<f32>, s: f32) -> vec3<f32> {
    return a * (1.0 - s) + b * s;
}
