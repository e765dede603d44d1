//! The wgpu device our kernels run on (training and nprt-render's frame path): one per
//! process, opened at first use.

use std::sync::{Arc, OnceLock};

use anyhow::{anyhow, Result};

use super::kernel::Pipelines;

/// A wgpu adapter's device and queue, and the kernels compiled for it.
pub struct GpuDevice {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// The adapter's name and driver, for reports ("llvmpipe (LLVM 19.1.7, 256 bits)" on
    /// Mesa's software Vulkan).
    pub adapter: String,
    pub(super) pipelines: Pipelines,
    /// Bound where a kernel's read-only input is unused, and where a written one is (two
    /// buffers: one dispatch may not bind a buffer both ways).
    pub empty: wgpu::Buffer,
    pub spare: wgpu::Buffer,
}

static DEVICE: OnceLock<Result<Arc<GpuDevice>, String>> = OnceLock::new();

impl GpuDevice {
    /// The process's GPU device, opened on first use: the first adapter wgpu finds on its
    /// native backends (Vulkan, Metal, DX12), preferring a high-performance one. An error
    /// says what is missing.
    pub fn get() -> Result<Arc<GpuDevice>> {
        DEVICE
            .get_or_init(|| Self::open().map(Arc::new).map_err(|e| format!("{e:#}")))
            .clone()
            .map_err(|e| anyhow!(e))
    }

    /// Whether the device opens here, for the tests and benchmarks that need one: where it
    /// does not, says why and answers false, unless `NPRT_REQUIRE_VULKAN` is set (scripts/test
    /// sets it once it has installed Mesa's software Vulkan), which makes that a panic.
    pub fn probe() -> bool {
        match Self::get() {
            Ok(gpu) => {
                eprintln!("adapter: {}", gpu.adapter);
                true
            }
            Err(e) if std::env::var_os("NPRT_REQUIRE_VULKAN").is_none() => {
                eprintln!("skipped: {e:#}");
                false
            }
            Err(e) => panic!("NPRT_REQUIRE_VULKAN is set but {e:#}"),
        }
    }

    fn open() -> Result<GpuDevice> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::PRIMARY;
        let instance = wgpu::Instance::new(desc);
        let adapter = futures_lite::future::block_on(instance.request_adapter(
            &wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                ..Default::default()
            },
        ))
        .map_err(|e| {
            anyhow!(
                "no GPU adapter found ({e}): nprt's GPU kernels need Vulkan, Metal or DX12; \
                 on Linux install a Vulkan driver (scripts/vulkan.sh installs Mesa's software \
                 one), or use --device cpu"
            )
        })?;
        let info = adapter.get_info();
        let (device, queue) =
            futures_lite::future::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
                label: Some("nprt"),
                // Timestamps only serve `nprt bench train --profile`; an adapter without them
                // still trains.
                required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
                // The adapter's own limits, not WebGPU's portable defaults (128 MiB per
                // storage binding, which a chunk of activations approaches).
                required_limits: adapter.limits(),
                experimental_features: wgpu::ExperimentalFeatures::disabled(),
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            }))
            .map_err(|e| anyhow!("the GPU adapter {} refused a device: {e}", info.name))?;
        let placeholder = |label| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 16,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        };
        Ok(GpuDevice {
            empty: placeholder("empty"),
            spare: placeholder("spare"),
            device,
            queue,
            adapter: format!("{} ({}, {:?})", info.name, info.driver_info, info.backend),
            pipelines: Pipelines::default(),
        })
    }

    /// Blocks until the queue's work is done.
    pub fn wait(&self) {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("waiting for the GPU queue");
    }
}
