// The visibility pass: every triangle rasterised through the camera, the nearest one's index
// (plus one; zero is the background) kept per pixel. Rasterisers sample at pixel centres, as
// the tracer's G-buffer does; `gbuffer.wgsl` then intersects the centre ray with the kept
// triangle to shade it exactly as the tracer would.

struct View {
    // World to clip: x and y scaled so that a pixel centre's ray lands on the pixel, depth
    // near / z (reversed, with the far plane at infinity).
    clip: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<storage, read> positions: array<f32>;
@group(0) @binding(2) var<storage, read> triangles: array<u32>;

struct Corner {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) id: u32,
}

@vertex
fn vertex(@builtin(vertex_index) i: u32) -> Corner {
    let tri = i / 3u;
    let v = triangles[4u * tri + i % 3u];
    let p = vec3<f32>(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
    return Corner(view.clip * vec4<f32>(p, 1.0), tri + 1u);
}

@fragment
fn fragment(c: Corner) -> @location(0) u32 {
    return c.id;
}
