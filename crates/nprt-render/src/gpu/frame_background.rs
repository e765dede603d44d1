//! A frame's background on the device: where the rasterised G-buffer sees nothing, the map
//! along the pixel-centre ray (as `background` does on the host), or zero where direct light
//! traced later brings the map there. The map's texels go up once per map, the rotation with
//! each frame.

use nprt_net::gpu::{GpuDevice, KernelSource};
use nprt_scene::{Camera, EnvMap};

use super::kept_last::KeptLast;
use super::raster_gbuffer::camera_words;

pub const FRAME_BACKGROUND: KernelSource = KernelSource {
    name: "frame_background",
    wgsl: concat!(
        include_str!("shaders/camera_ray.wgsl"),
        include_str!("shaders/map_lookup.wgsl"),
        include_str!("shaders/frame_background.wgsl")
    ),
};

/// The last map's texels on the device (a frame's background and the encoder's input read
/// them), kept with the map they came from.
#[derive(Default)]
pub struct GpuMap {
    kept: KeptLast<SameTexels, wgpu::Buffer>,
}

/// A map as a key: equal to another sharing its texels. It holds the map, so its texels cannot
/// be freed and another map's take their address while they are kept (an address alone as the
/// key gave a map loaded after another was dropped the dropped one's texels).
struct SameTexels(EnvMap);

impl PartialEq for SameTexels {
    fn eq(&self, other: &Self) -> bool {
        self.0.same_texels(&other.0)
    }
}

/// A 3 × 3 matrix as map_lookup.wgsl's callers take it: its columns, each padded to a vec4,
/// as u32 words of the parameter block (a map's world-to-local rotation).
pub(super) fn matrix_words(m: glam::Mat3) -> impl Iterator<Item = u32> {
    [m.x_axis, m.y_axis, m.z_axis]
        .into_iter()
        .flat_map(|c| c.extend(0.0).to_array().map(f32::to_bits))
}

/// What a frame's background needs: the G-buffer it fills the empty pixels of, its camera and
/// the map as placed in the world (None: zero, for direct light traced later).
pub struct Background<'a> {
    pub samples: &'a wgpu::Buffer,
    pub camera: &'a Camera,
    pub map: Option<&'a EnvMap>,
}

impl GpuMap {
    /// Records `background` into `rgb` (3 f32 per pixel).
    pub fn record(
        &self,
        gpu: &GpuDevice,
        pass: &mut wgpu::ComputePass,
        background: &Background,
        rgb: &wgpu::Buffer,
    ) {
        let camera = background.camera;
        let (texels, size, to_local) = match background.map {
            Some(map) => (
                self.texels(gpu, map),
                [map.width() as u32, map.height() as u32],
                map.to_world().inverse(),
            ),
            None => (gpu.empty.clone(), [1, 2], glam::Mat3::IDENTITY),
        };
        let fill = u32::from(background.map.is_some());
        let mut params = vec![camera.width, camera.height, size[0], size[1], fill, 0, 0, 0];
        params.extend(camera_words(camera));
        params.extend(matrix_words(to_local));
        gpu.dispatch(
            pass,
            &FRAME_BACKGROUND,
            &params,
            &[background.samples, &texels, rgb],
            [camera.width.div_ceil(8), camera.height.div_ceil(8)],
        );
    }

    /// `map`'s texels on the device, uploaded unless they were the last map's.
    pub(super) fn texels(&self, gpu: &GpuDevice, map: &EnvMap) -> wgpu::Buffer {
        self.kept.get(SameTexels(map.clone()), || {
            let flat: Vec<f32> = map.texels().iter().flat_map(|t| t.to_array()).collect();
            gpu.upload(&flat)
        })
    }
}
