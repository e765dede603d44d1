// Camera::ray's direction through film point `film` (in pixels) of a `size` film, for a camera
// whose to_world has the axes `x_axis`, `y_axis`, `z_axis` and whose half field of view has the
// tangents `tangents` (x, y); camera_ray through a pixel's centre. Shared by the frame's
// kernels that need camera rays.
fn camera_ray_at(film: vec2<f32>, size: vec2<u32>, x_axis: vec3<f32>, y_axis: vec3<f32>, z_axis: vec3<f32>, tangents: vec2<f32>) -> vec3<f32> {
    let s = film / vec2<f32>(size);
    let local = vec3<f32>((0.5 - s.x) * 2.0 * tangents.x, (0.5 - s.y) * 2.0 * tangents.y, 1.0);
    return normalize(x_axis * local.x + y_axis * local.y + z_axis * local.z);
}

fn camera_ray(pixel: vec2<u32>, size: vec2<u32>, x_axis: vec3<f32>, y_axis: vec3<f32>, z_axis: vec3<f32>, tangents: vec2<f32>) -> vec3<f32> {
    return camera_ray_at(vec2<f32>(pixel) + 0.5, size, x_axis, y_axis, z_axis, tangents);
}
