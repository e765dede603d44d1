//! The light model's input made on the device (what `LightInput::with_texels` makes on the
//! host): the map, rotated, looked up ss × ss times per input texel and averaged, then divided
//! by its `MapNorm` divisor and, for the encoder, taken through ln(1 + x). A lighting change
//! on the GPU then sends only the map's rotation, into dispatches prepared once per map; on
//! the host the lookups took a frame milliseconds (64 per texel of a 128-wide input from a
//! 1024-wide map).

use std::sync::LazyLock;

use crate::encoding::map_norm::MapNorm;
use crate::network::encoder::{LightInput, Texels};
use nprt_gpu::{groups_for, Dispatch, GpuDevice, KernelSource};
use nprt_scene::EnvMap;
use nprt_trace::gpu::wgsl::{LERP, MAP_LOOKUP};
use nprt_trace::gpu::{map_frame_words, GpuMap};

pub static LIGHT_TEXELS: LazyLock<KernelSource> = LazyLock::new(|| {
    KernelSource::joined(
        "light_texels",
        &[
            LERP,
            MAP_LOOKUP,
            include_str!("../shaders/light/light_texels.wgsl"),
        ],
    )
});

pub const LIGHT_NORMALISE: KernelSource = KernelSource {
    name: "light_normalise",
    wgsl: include_str!("../shaders/light/light_normalise.wgsl"),
};

/// A map made into the encoder's input on the device: `3 × width × width/2` values,
/// channel-major, and the divisor of each channel; with, for an input made from a map, the
/// dispatches that make it, kept so that each rotation only rewrites their parameters.
pub struct GpuLightInput {
    pub(super) pixels: wgpu::Buffer,
    pub(super) scale: wgpu::Buffer,
    pub width: usize,
    /// The texel lookups (into a buffer of their own), then the normalisation; none for an
    /// uploaded input.
    made: Vec<Dispatch>,
}

impl GpuLightInput {
    /// The dispatches that make `map`'s input for a `width`-wide light model normalised by
    /// `norm` and held as `held` (its texels uploaded into `kept` unless they are the last
    /// map's), prepared, not queued: [`Self::record`] queues them for a rotation.
    pub(super) fn for_map(
        gpu: &GpuDevice,
        kept: &GpuMap,
        map: &EnvMap,
        width: usize,
        norm: MapNorm,
        held: Texels,
    ) -> Self {
        let count = width * (width / 2);
        let texels = kept.texels(gpu, map);
        let rgb = gpu.buffer(3 * count);
        let (pixels, scale) = (gpu.buffer(3 * count), gpu.buffer(3));
        let norm_code = match norm {
            MapNorm::Mean => 0,
            MapNorm::Channel => 1,
        };
        let made = vec![
            gpu.prepare(
                &LIGHT_TEXELS,
                &texel_params(map, 0.0, width),
                &[&texels, &rgb],
                groups_for(count),
            ),
            gpu.prepare(
                &LIGHT_NORMALISE,
                &[count as u32, norm_code, u32::from(held == Texels::Log), 0],
                &[&rgb, &pixels, &scale],
                [1, 1],
            ),
        ];
        GpuLightInput {
            pixels,
            scale,
            width,
            made,
        }
    }

    /// Records the making of the input of `map` (the one it was prepared for) under
    /// `rotation_deg` about the vertical axis. The rotation reaches the device with the queue's
    /// next submission: submit before recording again.
    pub(super) fn record(
        &self,
        gpu: &GpuDevice,
        encoder: &mut wgpu::CommandEncoder,
        map: &EnvMap,
        rotation_deg: f32,
    ) {
        let texels = self.made.first().expect("an input made from a map");
        gpu.write(
            &texels.uniform,
            &texel_params(map, rotation_deg, self.width),
        );
        let mut pass = encoder.begin_compute_pass(&Default::default());
        for d in &self.made {
            d.record(&mut pass);
        }
    }

    /// The dispatches that make the input from its map (none for an uploaded input).
    pub(super) fn dispatches(&self) -> &[Dispatch] {
        &self.made
    }

    /// A pre-processed map uploaded as it is (the encoder's input made on the host).
    pub fn upload(gpu: &GpuDevice, input: &LightInput) -> Self {
        GpuLightInput {
            pixels: gpu.upload(&input.pixels),
            scale: gpu.upload(&input.scale),
            width: input.width,
            made: Vec::new(),
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

/// `light_texels`' parameters for `map` under `rotation_deg`, into an input `width` wide: its
/// size, the lookups per texel side (ss) and the rotated map.
fn texel_params(map: &EnvMap, rotation_deg: f32, width: usize) -> Vec<u32> {
    let ss = map.width().div_ceil(width).max(2);
    let mut params = [width, width / 2, ss, 0].map(|v| v as u32).to_vec();
    params.extend(map_frame_words(&map.rotated_y(rotation_deg)));
    params
}
