//! An environment map on the device: its texels (a frame's background, the encoder's input and
//! the path tracer read them) and its sampling table (the path tracer's), uploaded once per map.

use nprt_gpu::GpuDevice;
use nprt_scene::EnvMap;

use nprt_gpu::KeptLast;

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
pub struct SameTexels(pub EnvMap);

impl PartialEq for SameTexels {
    fn eq(&self, other: &Self) -> bool {
        self.0.same_texels(&other.0)
    }
}

/// A 3 × 3 matrix as the kernels take it: its columns, each padded to a vec4, as u32 words of
/// the parameter block.
pub fn matrix_words(m: glam::Mat3) -> impl Iterator<Item = u32> {
    [m.x_axis, m.y_axis, m.z_axis]
        .into_iter()
        .flat_map(|c| c.extend(0.0).to_array().map(f32::to_bits))
}

/// `map` as it lies in the world, as map_lookup.wgsl's `MapFrame` holds it in a kernel's
/// parameters: its world-to-local rotation, then its size.
pub fn map_frame_words(map: &EnvMap) -> impl Iterator<Item = u32> {
    let size = [map.width() as u32, map.height() as u32, 0, 0];
    matrix_words(map.to_world().inverse()).chain(size)
}

impl GpuMap {
    /// `map`'s sampling table on the device ([`nprt_scene::Distribution2D::cells`], three
    /// words a cell), uploaded unless it was the last map's.
    pub fn table(&self, gpu: &GpuDevice, map: &EnvMap) -> wgpu::Buffer {
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
    pub fn texels(&self, gpu: &GpuDevice, map: &EnvMap) -> wgpu::Buffer {
        self.kept.get(SameTexels(map.clone()), || {
            let flat: Vec<f32> = map.texels().iter().flat_map(|t| t.to_array()).collect();
            gpu.upload(&flat)
        })
    }
}
