// The 19 network inputs of a surface point, as nprt-net's pixel_features makes them (the CPU
// engine's, training's and the renderer's): the position normalised to [−1, 1] within the
// bounds whose minimum is `lo` and extent `extent` (at least 1e-6 per axis), ωo, ωr (ωo
// mirrored about n), n, kd, ks, α; written to row `r` of the including kernel's `features`.
fn put_features3(r: u32, k: u32, v: vec3<f32>) {
    features[19u * r + k] = v.x;
    features[19u * r + k + 1u] = v.y;
    features[19u * r + k + 2u] = v.z;
}

fn pixel_features(r: u32, position: vec3<f32>, normal: vec3<f32>, towards: vec3<f32>, kd: vec3<f32>, ks: vec3<f32>, alpha: f32, lo: vec3<f32>, extent: vec3<f32>) {
    put_features3(r, 0u, (position - lo) / extent * 2.0 - 1.0);
    put_features3(r, 3u, towards);
    put_features3(r, 6u, 2.0 * dot(normal, towards) * normal - towards);
    put_features3(r, 9u, normal);
    put_features3(r, 12u, kd);
    put_features3(r, 15u, ks);
    features[19u * r + 18u] = alpha;
}

