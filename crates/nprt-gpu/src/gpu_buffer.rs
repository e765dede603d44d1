//! Storage buffers on the device: made from host values, made empty, read back.

use wgpu::util::DeviceExt;

use crate::GpuDevice;

const STORAGE: wgpu::BufferUsages = wgpu::BufferUsages::STORAGE
    .union(wgpu::BufferUsages::COPY_SRC)
    .union(wgpu::BufferUsages::COPY_DST);

impl GpuDevice {
    /// Refuses `bytes` of `what` where one storage buffer on this device cannot hold and bind
    /// them, saying so (a kernel binds its inputs whole).
    pub fn check_binding(&self, bytes: usize, what: &str) -> anyhow::Result<()> {
        let most = self.max_binding_bytes();
        if bytes as u64 > most {
            anyhow::bail!(
                "{what} take {:.2} GB, more than one buffer on the GPU ({}) holds ({:.2} GB)",
                bytes as f64 / 1e9,
                self.adapter,
                most as f64 / 1e9
            );
        }
        Ok(())
    }

    /// Refuses a `width` × `height` frame (`what`) whose side passes the largest 2D texture
    /// this device makes (16,384 on most: the rasterised G-buffer is one texture), saying so
    /// before any of it is made.
    pub fn check_frame(&self, width: u32, height: u32, what: &str) -> anyhow::Result<()> {
        let most = self.device.limits().max_texture_dimension_2d;
        if width.max(height) > most {
            anyhow::bail!(
                "{what}: {width}×{height} pixels, but the GPU ({}) rasterises frames of at most {most} pixels a side; use a smaller frame or --device cpu",
                self.adapter
            );
        }
        Ok(())
    }

    /// The most bytes one storage buffer on this device holds and binds whole.
    pub fn max_binding_bytes(&self) -> u64 {
        let limits = self.device.limits();
        limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size)
    }

    /// The storage-binding alignment in 4-byte words (at least one): where a tensor bound on
    /// its own (a [`crate::Part`]) may start.
    pub fn binding_alignment(&self) -> usize {
        (self.device.limits().min_storage_buffer_offset_alignment as usize / 4).max(1)
    }

    /// A storage buffer holding `values` (f32, u32 or any plain words).
    pub fn upload<T: bytemuck::Pod>(&self, values: &[T]) -> wgpu::Buffer {
        // wgpu refuses empty bindings: an empty input still gets 16 bytes.
        let bytes: &[u8] = bytemuck::cast_slice(values);
        let padded;
        let contents = if bytes.len() < 16 {
            padded = [bytes, &[0; 16][bytes.len()..]].concat();
            &padded
        } else {
            bytes
        };
        self.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: None,
                contents,
                usage: STORAGE,
            })
    }

    /// A storage buffer of `floats` f32 (at least 4), zero.
    pub fn buffer(&self, floats: usize) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: (floats.max(4) * 4) as u64,
            usage: STORAGE,
            mapped_at_creation: false,
        })
    }

    /// A storage buffer of `halves` f16 values, zero.
    pub fn half_buffer(&self, halves: usize) -> wgpu::Buffer {
        self.buffer(halves.div_ceil(2))
    }

    /// Overwrites the start of `buffer` with `values`.
    pub fn write<T: bytemuck::Pod>(&self, buffer: &wgpu::Buffer, values: &[T]) {
        self.queue
            .write_buffer(buffer, 0, bytemuck::cast_slice(values));
    }

    /// The first `floats` values of `buffer`, once the queue's work is done.
    pub fn read(&self, buffer: &wgpu::Buffer, floats: usize) -> Vec<f32> {
        let size = (floats * 4) as u64;
        if size == 0 {
            return Vec::new();
        }
        let staging = self.staging.take_or(size, || {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("readback"),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        let submission = self.queue.submit([encoder.finish()]);
        let values = self.read_mapped(&staging, submission);
        self.staging.give([staging]);
        values
    }

    /// The values of `staging` (a host-readable buffer) once `submission`, which fills it, is
    /// done; `staging` is unmapped again after, to be filled anew.
    pub fn read_mapped<T: bytemuck::Pod>(
        &self,
        staging: &wgpu::Buffer,
        submission: wgpu::SubmissionIndex,
    ) -> Vec<T> {
        self.counted_wait();
        let slice = staging.slice(..);
        slice.map_async(wgpu::MapMode::Read, |r| {
            r.expect("mapping a GPU buffer for reading")
        });
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: Some(submission),
                timeout: None,
            })
            .expect("waiting for the GPU queue");
        let values = bytemuck::cast_slice(&slice.get_mapped_range().expect("mapped")).to_vec();
        staging.unmap();
        values
    }
}
