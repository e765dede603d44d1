//! A frame's background on the device: where the rasterised G-buffer sees nothing, the map
//! along the pixel-centre ray (as `background` does on the host); or, for a model that leaves
//! direct light to the tracer, zero there and that light traced on the device over every
//! pixel. The map's texels go up once per map, the rotation with each frame.

use nprt_net::gpu::{GpuDevice, KernelSource};
use nprt_scene::{Camera, EnvMap};

use super::kept_last::KeptLast;
use super::raster_gbuffer::{camera_words, RasterGBuffer};

pub const FRAME_BACKGROUND: KernelSource = KernelSource {
    name: "frame_background",
    wgsl: concat!(
        include_str!("shaders/camera_ray.wgsl"),
        include_str!("shaders/lerp.wgsl"),
        include_str!("shaders/map_lookup.wgsl"),
        include_str!("shaders/frame_background.wgsl")
    ),
};

/// The last map's texels on the device (a frame's background, the encoder's input and the path
/// tracer read them) and its sampling table (the path tracer's), kept with the map they came
/// from.
#[derive(Default)]
pub struct GpuMap {
    kept: KeptLast<SameTexels, wgpu::Buffer>,
    table: KeptLast<SameTexels, wgpu::Buffer>,
}

/// A map as a key: equal to another sharing its texels. It holds the map, so its texels cannot
/// be freed and another map's take their address while they are kept (an address alone as the
/// key gave a map loaded after another was dropped the dropped one's texels).
pub(super) struct SameTexels(pub(super) EnvMap);

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
/// what goes there.
pub struct Background<'a> {
    pub samples: &'a wgpu::Buffer,
    pub camera: &'a Camera,
    pub fill: Fill<'a>,
}

/// What a frame adds to the networks' radiance.
pub enum Fill<'a> {
    /// Nothing: the empty pixels zero.
    Zero,
    /// The map (as placed in the world) seen through the empty pixels.
    Map(&'a EnvMap),
    /// For a model that leaves direct light to the tracer, that light under the map, traced on
    /// the device: `spp` paths of two vertices through each pixel centre (which brings the
    /// map to the empty pixels).
    TracedDirect {
        map: &'a EnvMap,
        scene: &'a RasterGBuffer,
        spp: u32,
        seed: u64,
    },
}

impl GpuMap {
    /// Records `background` into `rgb` (3 f32 per pixel, the networks' radiance on the
    /// G-buffer's pixels).
    pub fn record(
        &self,
        gpu: &GpuDevice,
        pass: &mut wgpu::ComputePass,
        background: &Background,
        rgb: &wgpu::Buffer,
    ) {
        let camera = background.camera;
        let (map, fill) = match background.fill {
            Fill::Zero => (None, 0),
            Fill::Map(map) => (Some(map), 1),
            Fill::TracedDirect { map, .. } => (Some(map), 0),
        };
        let (texels, size, to_local) = match map {
            Some(map) => (
                self.texels(gpu, map),
                [map.width() as u32, map.height() as u32],
                map.to_world().inverse(),
            ),
            None => (gpu.empty.clone(), [1, 2], glam::Mat3::IDENTITY),
        };
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

    /// `map`'s sampling table on the device ([`nprt_scene::Distribution2D::cells`], three
    /// words a cell), uploaded unless it was the last map's.
    pub(super) fn table(&self, gpu: &GpuDevice, map: &EnvMap) -> wgpu::Buffer {
        self.table.get(SameTexels(map.clone()), || {
            let words: Vec<u32> = map
                .distribution()
                .cells()
                .flat_map(|(density, keep, alias)| [density.to_bits(), keep.to_bits(), alias])
                .collect();
            gpu.upload(&words)
        })
    }

    /// `map`'s texels on the device, uploaded unless they were the last map's.
    pub(super) fn texels(&self, gpu: &GpuDevice, map: &EnvMap) -> wgpu::Buffer {
        self.kept.get(SameTexels(map.clone()), || {
            let flat: Vec<f32> = map.texels().iter().flat_map(|t| t.to_array()).collect();
            gpu.upload(&flat)
        })
    }
}
