//! Storage buffers a camera's pixels hand back when they are dropped, for the next viewpoint's
//! pixels of the same size: a new viewpoint then reuses the G-buffer, features, ŝ and frame
//! buffers the last one had instead of allocating them (and having wgpu zero them) anew; on an
//! H200, allocating a 512² frame's activations anew for every viewpoint cost more than its
//! networks.

use std::sync::{Arc, Mutex};

use nprt_net::gpu::GpuDevice;

/// Buffers kept at most; the oldest go first.
const KEPT: usize = 32;

/// Buffers handed back, by size; clones share them.
#[derive(Clone, Default)]
pub struct BufferPool(Arc<Mutex<Vec<wgpu::Buffer>>>);

impl BufferPool {
    /// A buffer of `floats` f32 (as [`GpuDevice::buffer`] makes): one handed back of that size,
    /// its old values still in it, or a new one, zero.
    pub fn take(&self, gpu: &GpuDevice, floats: usize) -> wgpu::Buffer {
        let bytes = (floats.max(4) * 4) as u64;
        let mut kept = self.0.lock().unwrap_or_else(|e| e.into_inner());
        match kept.iter().position(|b| b.size() == bytes) {
            Some(i) => kept.remove(i),
            None => gpu.buffer(floats),
        }
    }

    /// Keeps `buffers` for a later [`Self::take`].
    pub fn give(&self, buffers: impl IntoIterator<Item = wgpu::Buffer>) {
        let mut kept = self.0.lock().unwrap_or_else(|e| e.into_inner());
        kept.extend(buffers);
        let over = kept.len().saturating_sub(KEPT);
        kept.drain(..over);
    }

    /// [`Self::take`], given back when the buffer is dropped.
    pub fn take_pooled(&self, gpu: &GpuDevice, floats: usize) -> PooledBuffer {
        PooledBuffer {
            buffer: self.take(gpu, floats),
            pool: self.clone(),
        }
    }
}

/// A buffer taken from a [`BufferPool`], handed back to it when dropped.
pub struct PooledBuffer {
    buffer: wgpu::Buffer,
    pool: BufferPool,
}

impl std::ops::Deref for PooledBuffer {
    type Target = wgpu::Buffer;

    fn deref(&self) -> &wgpu::Buffer {
        &self.buffer
    }
}

impl Drop for PooledBuffer {
    fn drop(&mut self) {
        self.pool.give([self.buffer.clone()]);
    }
}
