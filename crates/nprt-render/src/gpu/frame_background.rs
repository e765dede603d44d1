//! A frame's background on the device: where the rasterised G-buffer sees nothing, the map
//! along the pixel-centre ray (as `background` does on the host); or, for a model that leaves
//! direct light to the tracer, zero there and that light traced on the device over every
//! pixel. The map's texels go up once per map ([`GpuMap`]), the rotation with each frame.

use std::sync::LazyLock;

use nprt_gpu::{GpuDevice, KernelSource};
use nprt_scene::{Camera, EnvMap};
use nprt_trace::gpu::wgsl::{CAMERA_RAY, LERP, MAP_LOOKUP};
use nprt_trace::gpu::{camera_words, map_frame_words, GpuMap};

pub static FRAME_BACKGROUND: LazyLock<KernelSource> = LazyLock::new(|| {
    KernelSource::joined(
        "frame_background",
        &[
            CAMERA_RAY,
            LERP,
            MAP_LOOKUP,
            include_str!("shaders/frame_background.wgsl"),
        ],
    )
});

/// What a frame's background needs: the G-buffer it fills the empty pixels of, its camera and
/// what goes there.
pub struct Background<'a> {
    pub samples: &'a wgpu::Buffer,
    pub camera: &'a Camera,
    pub fill: Fill<'a>,
}

/// What a frame adds to the networks' radiance.
pub enum Fill<'a> {
    /// The map (as placed in the world) seen through the empty pixels.
    Map(&'a EnvMap),
    /// For a model that leaves direct light to the tracer: the empty pixels zero, as that
    /// light, traced on the device under the map through each pixel centre, brings the map
    /// there (`DeviceStages`).
    TracedDirect(&'a EnvMap),
}

/// Records `background` into `rgb` (3 f32 per pixel, the networks' radiance on the G-buffer's
/// pixels), the map's texels kept in `maps`.
pub fn record_background(
    maps: &GpuMap,
    gpu: &GpuDevice,
    pass: &mut wgpu::ComputePass,
    background: &Background,
    rgb: &wgpu::Buffer,
) {
    let camera = background.camera;
    let (map, fill) = match background.fill {
        Fill::Map(map) => (map, 1),
        Fill::TracedDirect(map) => (map, 0),
    };
    let texels = maps.texels(gpu, map);
    let mut params = vec![camera.width, camera.height, fill, 0];
    params.extend(camera_words(camera));
    params.extend(map_frame_words(map));
    gpu.dispatch(
        pass,
        &FRAME_BACKGROUND,
        &params,
        &[background.samples, &texels, rgb],
        [camera.width.div_ceil(8), camera.height.div_ceil(8)],
    );
}
