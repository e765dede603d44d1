//! A training set held on the device: every record of its pack as it lies in the file (40 bytes
//! a pixel, docs/dataset.md), and each training view's pre-processed map and scale, uploaded
//! once, so that a step gathers its batch there from the sample picks alone
//! (`shaders/encodings/gather_samples.wgsl`) instead of taking the batch's inputs from the host.

use anyhow::{bail, Context, Result};
use nprt_data::dataset::PACKED_PIXEL_BYTES;

use glam::Vec3;

use crate::encoding::features::position_frame;
use crate::network::encoder::LightInput;
use nprt_data::dataset::PackedDataset;
use nprt_gpu::GpuDevice;

/// Records per upload: large enough to keep the queue's copies few, small enough that their
/// staging stays modest.
const UPLOAD_RECORDS: usize = 1 << 20;

const _: () = assert!(
    PACKED_PIXEL_BYTES == 40,
    "shaders/encodings/gather_samples.wgsl reads a record as 10 words"
);

/// The pack's records from `first` on, in one storage buffer.
pub(crate) struct Shard {
    pub records: wgpu::Buffer,
    pub first: u32,
    pub count: u32,
}

/// A training set on the device.
pub struct DeviceDataset {
    /// The records, cut where a buffer would pass the device's binding limit.
    pub(crate) shards: Vec<Shard>,
    /// Per training view: its map (`light_floats` each) and its scale (3 each).
    pub(crate) lights: wgpu::Buffer,
    pub(crate) scales: wgpu::Buffer,
    pub(crate) light_floats: usize,
    /// The gather kernel's bounds: the pack's minimum, extent, and the extent positions are
    /// normalised by, as vec4s.
    pub(crate) bounds: [f32; 12],
    /// Bytes held on the device.
    pub bytes: u64,
}

impl DeviceDataset {
    /// Uploads a training set's pack and its training views' maps to `gpu`; says so where the
    /// device lacks the memory.
    pub fn upload(gpu: &GpuDevice, pack: &PackedDataset, maps: &[&LightInput]) -> Result<Self> {
        let records = pack.records();
        if records.len() > u32::MAX as usize {
            bail!(
                "the pack holds {} records, more than a GPU step indexes (2³²)",
                records.len()
            );
        }
        let per_shard = gpu
            .max_binding_bytes()
            .div_euclid(PACKED_PIXEL_BYTES as u64) as usize;
        let light_floats = maps.first().map_or(0, |m| m.pixels.len());
        let lights: Vec<f32> = maps.iter().flat_map(|m| m.pixels.iter().copied()).collect();
        let scales: Vec<f32> = maps.iter().flat_map(|m| m.scale).collect();
        gpu.check_binding(4 * lights.len(), "the training views' maps")
            .context("train with --gather host or a smaller --encoder-width")?;
        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let mut shards = Vec::new();
        for (k, chunk) in records.chunks(per_shard.max(1)).enumerate() {
            let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("dataset records"),
                size: std::mem::size_of_val(chunk).max(16) as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            for (j, part) in chunk.chunks(UPLOAD_RECORDS).enumerate() {
                let at = (j * UPLOAD_RECORDS * PACKED_PIXEL_BYTES) as u64;
                gpu.queue
                    .write_buffer(&buffer, at, bytemuck::cast_slice(part));
            }
            shards.push(Shard {
                records: buffer,
                first: (k * per_shard) as u32,
                count: chunk.len() as u32,
            });
        }
        let lights = gpu.upload(&lights);
        let scales = gpu.upload(&scales);
        if let Some(e) = futures_lite::future::block_on(scope.pop()) {
            return Err(anyhow::anyhow!("{e}")).context(format!(
                "the GPU ({}) has no room for the dataset's {} records and {} maps; train with \
                 --gather host",
                gpu.adapter,
                records.len(),
                maps.len()
            ));
        }
        let pack_bounds = &pack.header().bounds;
        let (lo, normaliser) = position_frame(pack_bounds);
        // The records' positions are stored within the bounds' own extent, unclamped.
        let extent = Vec3::from(pack_bounds[1]) - lo;
        let mut bounds = [0.0; 12];
        for (k, v) in [lo, extent, normaliser].iter().enumerate() {
            bounds[4 * k..4 * k + 3].copy_from_slice(&v.to_array());
        }
        Ok(DeviceDataset {
            shards,
            light_floats,
            bounds,
            bytes: (std::mem::size_of_val(records) + 4 * (light_floats + 3) * maps.len()) as u64,
            lights,
            scales,
        })
    }
}
