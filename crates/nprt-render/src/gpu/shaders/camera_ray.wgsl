// Camera::ray's direction through the centre of pixel `pixel` of a `size` film, for a camera
// whose to_world has the axes `x_axis`, `y_axis`, `z_axis` and whose half field of view has the
// tangents `tangents` (x, y). Shared by the frame's kernels that need the pixel-centre rays.
fn camera_ray(pixel: vec2<u32>, size: vec2<u32>, x_axis: vec3<f32>, y_axis: vec3<f32>, z_axis: vec3<f32>, tangents: vec2<f32>) -> vec3<f32> {
    let s = (vec2<f32>(pixel) + 0.5) / vec2<f32>(size);
    let local = vec3<f32>((0.5 - s.x) * 2.0 * tangents.x, (0.5 - s.y) * 2.0 * tangents.y, 1.0);
    return normalize(x_axis * local.x + y_axis * local.y + z_axis * local.z);
}

