//! Where the networks run: the `--device` choice of every command that trains or infers,
//! resolved once into an [`Engine`]: the CPU engine, or nprt's own GPU kernels on wgpu (any
//! Vulkan, Metal or DX12 adapter; Mesa's software Vulkan driver, lavapipe, when asked for by
//! name, which is how CI tests the kernels without a GPU). Both read and write the weights
//! `network` defines, so a model folder, and a checkpoint with Adam's state, is the same
//! whichever trained it.

use anyhow::{bail, Result};
use nprt_trace::TraceDevice;

use crate::choice::named_choice;
use crate::cpu::HostCacheSteps;
use crate::network::radiance_cache::{CacheSteps, RadianceCache, ADAM_BETAS};
use crate::network::unet::DeepShading;
use crate::optimiser::Adam;
use crate::parameters::Parameters;
use crate::shading::UnetShading;

/// `--device`: the CPU, a GPU (hardware adapters only), any wgpu adapter (software ones
/// included), or a GPU when one is present.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Compute {
    Cpu,
    Gpu,
    Wgpu,
    #[default]
    Auto,
}

named_choice!(Compute, "device", {
    Cpu => "cpu",
    Gpu => "gpu",
    Wgpu => "wgpu",
    Auto => "auto",
});

/// What runs the networks: the CPU engine (`crate::cpu`) or the GPU kernels (`crate::gpu`, on
/// the process's one wgpu device).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Engine {
    Cpu,
    Gpu,
}

impl Compute {
    /// The engine `--device` names. `gpu` without a hardware adapter, or `gpu`/`wgpu` in a
    /// build without the kernels, is an error naming what is missing; `auto` takes a hardware
    /// adapter when there is one, else the CPU, and says why on standard error in a build with
    /// the kernels (where a GPU could have been meant).
    pub fn engine(self) -> Result<Engine> {
        match self {
            Compute::Cpu => Ok(Engine::Cpu),
            Compute::Wgpu => any_adapter(),
            Compute::Gpu => match no_hardware_gpu() {
                None => Ok(Engine::Gpu),
                Some(why) => bail!("--device gpu: {why}"),
            },
            Compute::Auto => Ok(match no_hardware_gpu() {
                None => Engine::Gpu,
                Some(why) => {
                    if cfg!(feature = "gpu") {
                        eprintln!("--device auto: running on the CPU: {why}");
                    }
                    Engine::Cpu
                }
            }),
        }
    }
}

/// Why the GPU kernels cannot run on a hardware adapter here, or None when they can.
#[cfg(feature = "gpu")]
fn no_hardware_gpu() -> Option<String> {
    match nprt_gpu::GpuDevice::get() {
        Err(e) => Some(format!("{e:#}")),
        Ok(gpu) if gpu.software => Some(format!(
            "the only GPU adapter is a software one ({}); --device wgpu runs the GPU kernels \
             on it, --device cpu the CPU engine",
            gpu.adapter
        )),
        Ok(_) => None,
    }
}

#[cfg(not(feature = "gpu"))]
fn no_hardware_gpu() -> Option<String> {
    Some(WITHOUT_KERNELS.into())
}

/// The GPU kernels on whatever adapter wgpu finds, software ones included.
#[cfg(feature = "gpu")]
fn any_adapter() -> Result<Engine> {
    nprt_gpu::GpuDevice::get().map(|_| Engine::Gpu)
}

#[cfg(not(feature = "gpu"))]
fn any_adapter() -> Result<Engine> {
    bail!("--device wgpu: {WITHOUT_KERNELS}")
}

#[cfg(not(feature = "gpu"))]
const WITHOUT_KERNELS: &str = "this nprt was built without its GPU kernels; rebuild it with \
    `cargo build --release --features gpu` (docs/building.md), or use --device cpu";

impl From<TraceDevice> for Engine {
    /// The engine on the device `tracer` runs on.
    fn from(tracer: TraceDevice) -> Self {
        match tracer {
            TraceDevice::Cpu => Engine::Cpu,
            TraceDevice::Gpu => Engine::Gpu,
        }
    }
}

impl Engine {
    pub fn is_gpu(self) -> bool {
        self == Engine::Gpu
    }

    /// The trained Deep Shading U-Net `net` on this engine (one view at a time on the GPU).
    pub fn unet(self, net: DeepShading) -> Result<Box<dyn UnetShading>> {
        match self {
            Engine::Cpu => Ok(Box::new(net)),
            #[cfg(feature = "gpu")]
            Engine::Gpu => Ok(Box::new(std::sync::Mutex::new(crate::gpu::GpuUnet::new(
                &net,
            )?))),
            #[cfg(not(feature = "gpu"))]
            Engine::Gpu => bail!("--device gpu: {WITHOUT_KERNELS}"),
        }
    }

    /// The radiance cache `cache` to train online on this engine, under the cache's Adam
    /// betas.
    pub fn cache_steps(self, cache: RadianceCache) -> Result<Box<dyn CacheSteps>> {
        match self {
            Engine::Cpu => Ok(Box::new(HostCacheSteps {
                adam: Adam::with_betas(cache.num_params(), ADAM_BETAS),
                cache,
            })),
            #[cfg(feature = "gpu")]
            Engine::Gpu => Ok(Box::new(crate::gpu::GpuCache::new(&cache, ADAM_BETAS)?)),
            #[cfg(not(feature = "gpu"))]
            Engine::Gpu => bail!("--device gpu: {WITHOUT_KERNELS}"),
        }
    }

    /// The path tracer on this engine's device (`nprt generate --device`).
    pub fn tracer(self) -> TraceDevice {
        match self {
            Engine::Cpu => TraceDevice::Cpu,
            Engine::Gpu => TraceDevice::Gpu,
        }
    }

    /// A short name for progress lines and reports: "cpu", or "gpu: " and the adapter's name
    /// ("gpu: llvmpipe (LLVM 19.1.7, 256 bits)").
    pub fn name(self) -> String {
        match self {
            Engine::Cpu => "cpu".into(),
            #[cfg(feature = "gpu")]
            Engine::Gpu => match nprt_gpu::GpuDevice::get() {
                Ok(gpu) => format!("gpu: {}", gpu.adapter),
                Err(_) => "gpu".into(),
            },
            #[cfg(not(feature = "gpu"))]
            Engine::Gpu => "gpu".into(),
        }
    }
}

/// Waits for the work queued on the GPU, if this process opened it. Called once a command is
/// done: work still running at exit would run after the driver had shut down.
pub fn finish() {
    #[cfg(feature = "gpu")]
    if let Some(gpu) = nprt_gpu::GpuDevice::opened() {
        gpu.wait();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn devices_resolve_to_engines_and_auto_falls_back_to_the_cpu() {
        assert_eq!(Compute::Cpu.engine().unwrap(), Engine::Cpu);
        match Compute::Gpu.engine() {
            Ok(engine) => assert!(engine.is_gpu()),
            Err(e) if cfg!(feature = "gpu") => {
                let e = format!("{e:#}");
                assert!(
                    e.contains("software one") || e.contains("no GPU adapter"),
                    "{e}"
                );
                assert_eq!(Compute::Auto.engine().unwrap(), Engine::Cpu);
            }
            Err(e) => {
                assert!(
                    e.to_string().contains("built without its GPU kernels"),
                    "{e}"
                );
                assert_eq!(Compute::Auto.engine().unwrap(), Engine::Cpu);
                assert!(Compute::Wgpu.engine().is_err());
            }
        }
        assert_eq!("gpu".parse::<Compute>(), Ok(Compute::Gpu));
        assert!("tpu"
            .parse::<Compute>()
            .unwrap_err()
            .contains("cpu, gpu, wgpu or auto"));
        assert_eq!("wgpu".parse::<Compute>(), Ok(Compute::Wgpu));
    }
}
