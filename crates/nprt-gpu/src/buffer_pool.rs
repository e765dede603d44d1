//! Buffers kept for reuse: handed back when their user is done, and taken by the next user of
//! the same size instead of a new one, which wgpu would allocate and zero. The frame path keeps
//! a viewpoint's G-buffer, features, ŝ and frame for the next viewpoint (on an H200, allocating
//! a 512² frame's activations anew for every viewpoint cost more than its networks); the device
//! keeps the host-readable buffers that reads copy into.

use std::sync::{Arc, Mutex};

use crate::{Bind, GpuDevice};

/// Buffers handed back, by size, the oldest dropped past a bound; clones share them.
#[derive(Clone)]
pub struct BufferPool {
    kept: Arc<Mutex<Vec<wgpu::Buffer>>>,
    most: usize,
}

impl Default for BufferPool {
    /// A pool of at most 32 buffers: a viewpoint's dozen or so, twice over.
    fn default() -> Self {
        Self::new(32)
    }
}

impl BufferPool {
    /// A pool keeping at most `most` buffers.
    pub fn new(most: usize) -> Self {
        BufferPool {
            kept: Arc::default(),
            most,
        }
    }

    /// A buffer of `bytes`: one handed back of that size, its old values still in it, or
    /// `make`'s.
    pub fn take_or(&self, bytes: u64, make: impl FnOnce() -> wgpu::Buffer) -> wgpu::Buffer {
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        match kept.iter().position(|b| b.size() == bytes) {
            Some(i) => kept.remove(i),
            None => make(),
        }
    }

    /// A storage buffer of `floats` f32 (as [`GpuDevice::buffer`] makes): one handed back of
    /// that size, or a new one, zero.
    pub fn take(&self, gpu: &GpuDevice, floats: usize) -> wgpu::Buffer {
        self.take_or((floats.max(4) * 4) as u64, || gpu.buffer(floats))
    }

    /// Keeps `buffers` for a later take.
    pub fn give(&self, buffers: impl IntoIterator<Item = wgpu::Buffer>) {
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        kept.extend(buffers);
        let over = kept.len().saturating_sub(self.most);
        kept.drain(..over);
    }

    /// [`Self::take`], given back when the buffer is dropped.
    pub fn take_pooled(&self, gpu: &GpuDevice, floats: usize) -> PooledBuffer {
        self.hold(self.take(gpu, floats))
    }

    /// `buffer`, given to this pool when it is dropped.
    pub fn hold(&self, buffer: wgpu::Buffer) -> PooledBuffer {
        PooledBuffer {
            buffer,
            pool: self.clone(),
        }
    }
}

/// A buffer given to a [`BufferPool`] when dropped.
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

impl Bind for PooledBuffer {
    fn resource(&self) -> wgpu::BindingResource<'_> {
        self.buffer.as_entire_binding()
    }
}

impl Drop for PooledBuffer {
    fn drop(&mut self) {
        self.pool.give([self.buffer.clone()]);
    }
}
