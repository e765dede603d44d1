//! The encoder's input made on the device (what `LightInput::new` makes on the host): the map,
//! rotated, looked up ss × ss times per input texel and averaged, then divided by its
//! `MapNorm` divisor and taken through ln(1 + x). A lighting change on the GPU then sends only
//! the map's rotation; on the host the lookups took a frame milliseconds (64 per texel of a
//! 128-wide input from a 1024-wide map).

use nprt_net::gpu::{groups_for, GpuDevice, KernelSource};
use nprt_net::{LightInput, MapNorm};
use nprt_scene::EnvMap;

use super::frame_background::{matrix_words, GpuMap};

pub const LIGHT_TEXELS: KernelSource = KernelSource {
    name: "light_texels",
    wgsl: concat!(
        include_str!("shaders/lerp.wgsl"),
        include_str!("shaders/map_lookup.wgsl"),
        include_str!("shaders/light_texels.wgsl")
    ),
};

pub const LIGHT_NORMALISE: KernelSource = KernelSource {
    name: "light_normalise",
    wgsl: include_str!("shaders/light_normalise.wgsl"),
};

/// A map made into the encoder's input on the device: `3 × width × width/2` values,
/// channel-major, and the divisor of each channel.
pub struct GpuLightInput {
    pub(super) pixels: wgpu::Buffer,
    pub(super) scale: wgpu::Buffer,
    pub width: usize,
}

impl GpuLightInput {
    /// `map` under `rotation_deg` about the vertical axis, made into the input of a
    /// `width`-wide encoder normalised by `norm` (its texels uploaded into `kept` unless they
    /// are the last map's).
    pub(super) fn new(
        gpu: &GpuDevice,
        kept: &GpuMap,
        map: &EnvMap,
        rotation_deg: f32,
        width: usize,
        norm: MapNorm,
    ) -> Self {
        let height = width / 2;
        let count = width * height;
        let rotated = map.rotated_y(rotation_deg);
        let to_local = rotated.to_world().inverse();
        let ss = map.width().div_ceil(width).max(2);
        let texels = kept.texels(gpu, map);
        let rgb = gpu.buffer(3 * count);
        let input = GpuLightInput {
            pixels: gpu.buffer(3 * count),
            scale: gpu.buffer(3),
            width,
        };
        let mut params = [width, height, ss, map.width(), map.height(), 0, 0, 0]
            .map(|v| v as u32)
            .to_vec();
        params.extend(matrix_words(to_local));
        let norm_code = match norm {
            MapNorm::Mean => 0,
            MapNorm::Channel => 1,
        };
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            gpu.dispatch(
                &mut pass,
                &LIGHT_TEXELS,
                &params,
                &[&texels, &rgb],
                groups_for(count),
            );
            gpu.dispatch(
                &mut pass,
                &LIGHT_NORMALISE,
                &[count as u32, norm_code, 0, 0],
                &[&rgb, &input.pixels, &input.scale],
                [1, 1],
            );
        }
        gpu.queue.submit([encoder.finish()]);
        input
    }

    /// A pre-processed map uploaded as it is (the encoder's input made on the host).
    pub fn upload(gpu: &GpuDevice, input: &LightInput) -> Self {
        GpuLightInput {
            pixels: gpu.upload(&input.pixels),
            scale: gpu.upload(&input.scale),
            width: input.width,
        }
    }

    /// The input's values, read back (to compare with the host's).
    pub fn read(&self, gpu: &GpuDevice) -> LightInput {
        let count = 3 * self.width * (self.width / 2);
        let scale = gpu.read(&self.scale, 3);
        LightInput {
            pixels: gpu.read(&self.pixels, count),
            scale: [scale[0], scale[1], scale[2]],
            width: self.width,
        }
    }
}
