//! nprt-gpu: the GPU runtime our own WGSL kernels run on, below every stage that has kernels
//! (nprt-trace's path tracer and G-buffer, nprt-net's networks and training step, nprt-render's
//! frames). It owns the wgpu device (one per process, the best adapter first), storage buffers
//! made, written and read back, the pool that keeps buffers for reuse, how a kernel is compiled
//! and dispatched (a uniform block at binding 0, storage buffers after it), and the timers that
//! profile a recorded list of dispatches.
//!
//! It must not hold a kernel of its own or know what a kernel computes: WGSL sources, their
//! parameters and the order of dispatches belong to the stage whose CPU code they mirror, where
//! tests hold the two together.
//!
//! ```
//! use nprt_gpu::GpuDevice;
//!
//! // Skips where no adapter opens, unless NPRT_REQUIRE_VULKAN makes that a failure.
//! if GpuDevice::probe() {
//!     let gpu = GpuDevice::get().unwrap();
//!     let buffer = gpu.upload(&[1.5f32, -2.0, 3.25]);
//!     assert_eq!(gpu.read(&buffer, 3), [1.5, -2.0, 3.25]);
//! }
//! ```

mod buffer_pool;
mod gpu_buffer;
mod gpu_device;
mod kept_last;
mod kernel;
mod kernel_timer;
mod span;

pub use buffer_pool::{BufferPool, PooledBuffer};
pub use gpu_device::GpuDevice;
pub use kept_last::KeptLast;
pub use kernel::{groups_for, Bind, Dispatch, KernelSource, Part, GROUP};
pub use kernel_timer::{KernelTime, KernelTimer};
pub use span::Span;
