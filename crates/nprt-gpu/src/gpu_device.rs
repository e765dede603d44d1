//! The wgpu device our kernels run on (training and nprt-render's frame path): one per
//! process, opened at first use.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};

use anyhow::{anyhow, Result};

use crate::kernel::Pipelines;
use crate::BufferPool;

/// A wgpu adapter's device and queue, and the kernels compiled for it.
pub struct GpuDevice {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// The instance and adapter it came from: `nprt view` draws into its window with this
    /// device, so that frames the kernels leave on it are shown without a trip to the host.
    pub instance: wgpu::Instance,
    pub wgpu_adapter: wgpu::Adapter,
    /// The adapter's name and driver, for reports ("llvmpipe (LLVM 19.1.7, 256 bits)" on
    /// Mesa's software Vulkan).
    pub adapter: String,
    /// Whether the adapter is a software rasteriser (lavapipe, WARP), which `--device gpu` and
    /// `auto` pass over.
    pub software: bool,
    /// Whether kernels may hold f16 values (`half_layer`, the frame path's `--precision f16`).
    pub half: bool,
    /// Whether `half_layer`'s products run on cooperative matrices (tensor cores): 16 × 16 × 16
    /// f16 products into f32, in subgroups of 32; never with `NPRT_TENSOR_CORES=off`.
    pub tensor_cores: bool,
    pub(crate) pipelines: Pipelines,
    /// Bound where a kernel's read-only input is unused, and where a written one is (two
    /// buffers: one dispatch may not bind a buffer both ways).
    pub empty: wgpu::Buffer,
    pub spare: wgpu::Buffer,
    /// Host-readable buffers that reads copied into, kept for the next read of the same size
    /// (a frame read back every lighting change otherwise allocated one of its size each time).
    pub(crate) staging: BufferPool,
    /// Times the host has waited for the queue ([`Self::host_waits`]).
    waits: AtomicU64,
}

/// Host-readable buffers [`GpuDevice::read`] keeps at most.
const STAGING_KEPT: usize = 8;

static DEVICE: OnceLock<Result<Arc<GpuDevice>, String>> = OnceLock::new();

impl GpuDevice {
    /// The process's GPU device, opened on first use: the best adapter wgpu finds on its
    /// native backends (Vulkan, Metal, DX12), a discrete GPU first and a software one last. An
    /// error says what is missing.
    pub fn get() -> Result<Arc<GpuDevice>> {
        DEVICE
            .get_or_init(|| Self::open().map(Arc::new).map_err(|e| format!("{e:#}")))
            .clone()
            .map_err(|e| anyhow!(e))
    }

    /// The device if this process has opened it.
    pub fn opened() -> Option<Arc<GpuDevice>> {
        DEVICE.get()?.as_ref().ok().cloned()
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
        let adapters =
            futures_lite::future::block_on(instance.enumerate_adapters(wgpu::Backends::PRIMARY));
        let adapter = adapters
            .into_iter()
            .min_by_key(|a| adapter_rank(a.get_info().device_type))
            .ok_or_else(|| {
                anyhow!(
                    "no GPU adapter found: nprt's GPU kernels need Vulkan, Metal or DX12; on \
                     Linux install a Vulkan driver (scripts/vulkan.sh installs Mesa's software \
                     one), or use --device cpu"
                )
            })?;
        let info = adapter.get_info();
        let half = adapter.features().contains(wgpu::Features::SHADER_F16);
        let asked = std::env::var_os(TENSOR_CORES_VAR).map(|v| v.to_string_lossy().into_owned());
        let tensor_cores =
            half && tensor_cores_allowed(asked.as_deref())? && tensor_cores(&adapter);
        // Timestamps only serve `nprt bench train --profile`; an adapter without them still
        // trains. f16 and tensor cores serve the frame path's `--precision f16`.
        let mut features = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
        features.set(wgpu::Features::SHADER_F16, half);
        features.set(
            wgpu::Features::EXPERIMENTAL_COOPERATIVE_MATRIX,
            tensor_cores,
        );
        let (device, queue) =
            futures_lite::future::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
                label: Some("nprt"),
                required_features: features,
                // The adapter's own limits, not WebGPU's portable defaults (128 MiB per
                // storage binding, which a chunk of activations approaches).
                required_limits: adapter.limits(),
                // wgpu's cooperative matrices are experimental: asked for only where the
                // adapter offers the one configuration `half_dense_coop` uses.
                experimental_features: if tensor_cores {
                    // SAFETY: the kernels use cooperative matrices only as naga validates them,
                    // in the configuration the adapter reports.
                    unsafe { wgpu::ExperimentalFeatures::enabled() }
                } else {
                    wgpu::ExperimentalFeatures::disabled()
                },
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
            instance,
            wgpu_adapter: adapter.clone(),
            adapter: format!("{} ({}, {:?})", info.name, info.driver_info, info.backend),
            software: info.device_type == wgpu::DeviceType::Cpu,
            half,
            tensor_cores,
            pipelines: Pipelines::default(),
            staging: BufferPool::new(STAGING_KEPT),
            waits: AtomicU64::new(0),
        })
    }

    /// Whether the frame path can run its networks in half precision here.
    pub fn check_half(&self) -> Result<()> {
        if self.half {
            Ok(())
        } else {
            Err(anyhow!(
                "--precision f16 needs f16 in shaders, which the GPU adapter {} lacks; use \
                 --precision f32",
                self.adapter
            ))
        }
    }

    /// Blocks until the queue's work is done.
    pub fn wait(&self) {
        self.counted_wait();
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("waiting for the GPU queue");
    }

    /// How many times the host has waited for the queue since the device opened (a wait, or a
    /// read back): what `nprt bench frame` counts per lighting change, and tests bound.
    pub fn host_waits(&self) -> u64 {
        self.waits.load(Ordering::Relaxed)
    }

    pub(crate) fn counted_wait(&self) {
        self.waits.fetch_add(1, Ordering::Relaxed);
    }
}

/// The order adapters are preferred in: a discrete GPU first, a software one last.
fn adapter_rank(kind: wgpu::DeviceType) -> u8 {
    match kind {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

/// The environment variable that turns the tensor-core kernels off (`off`) where the adapter
/// has them.
const TENSOR_CORES_VAR: &str = "NPRT_TENSOR_CORES";

/// Whether the tensor-core kernels may run, from [`TENSOR_CORES_VAR`]'s value: unset or `on`,
/// where the adapter has them; `off`, never (the plain kernels, which compute the same sums,
/// run instead: the way past a tensor-core kernel that fails on a device, and a way to time
/// the two on one GPU).
fn tensor_cores_allowed(value: Option<&str>) -> Result<bool> {
    match value {
        None | Some("on") => Ok(true),
        Some("off") => Ok(false),
        Some(other) => Err(anyhow!(
            "{TENSOR_CORES_VAR} is '{other}': set it to on or off, or leave it unset"
        )),
    }
}

/// Whether `adapter` offers cooperative matrices of 16 × 16 × 16 f16 products into f32 in
/// subgroups of 32 (what `half_dense_coop` is written for).
fn tensor_cores(adapter: &wgpu::Adapter) -> bool {
    let info = adapter.get_info();
    adapter
        .features()
        .contains(wgpu::Features::EXPERIMENTAL_COOPERATIVE_MATRIX)
        && info.subgroup_min_size == 32
        && info.subgroup_max_size == 32
        && adapter.cooperative_matrix_properties().iter().any(|c| {
            (c.m_size, c.n_size, c.k_size) == (16, 16, 16)
                && c.ab_type == wgpu::CooperativeScalarType::F16
                && c.cr_type == wgpu::CooperativeScalarType::F32
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// NPRT_TENSOR_CORES: unset or `on` leaves the choice to the adapter, `off` refuses tensor
    /// cores, anything else is an error that names the variable and its value.
    #[test]
    fn the_tensor_core_switch_takes_on_and_off_only() {
        assert!(tensor_cores_allowed(None).unwrap());
        assert!(tensor_cores_allowed(Some("on")).unwrap());
        assert!(!tensor_cores_allowed(Some("off")).unwrap());
        let e = tensor_cores_allowed(Some("0")).unwrap_err().to_string();
        assert!(e.contains("NPRT_TENSOR_CORES is '0'"), "{e}");
    }
}
