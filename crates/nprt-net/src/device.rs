//! Where the networks run: the `--device` choice of every command that trains or infers, and
//! the one place that turns it into a burn [`Device`]. Model code never asks; it runs on the
//! device its tensors live on, so a model folder is the same whichever trained it.
//!
//! Two GPU routes share burn's one set of GPU kernels (cubecl): CUDA (`gpu`), and wgpu
//! (`wgpu`: Vulkan or Metal, whatever the vendor). The second also runs on a software Vulkan
//! driver (Mesa's lavapipe), which is how CI, without a GPU, tests the GPU code path. Each is
//! compiled in only with the cargo feature of its name (`cuda`, `wgpu`); a build without one
//! says so when that device is asked for.

use anyhow::{bail, Result};
use burn::tensor::{Device, TensorData};

use crate::choice::named_choice;

/// `--device`: the CPU, an NVIDIA GPU through CUDA, any GPU through wgpu, or the CUDA GPU
/// when one is present.
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

impl Compute {
    /// The device to run on. `gpu` without a usable CUDA device, or `wgpu` without a Vulkan
    /// or Metal adapter, is an error naming what is missing; `auto` falls back to the CPU
    /// (it never picks wgpu, which may be a software driver slower than the CPU engine).
    /// The chosen device also becomes burn's default (see [`make_default`]).
    pub fn device(self) -> Result<Device> {
        let device = match self {
            Compute::Cpu => Device::flex(),
            Compute::Gpu if !cfg!(feature = "cuda") => bail!(
                "--device gpu: this nprt was built without CUDA support; rebuild it with \
                 `cargo build --release --features cuda` (docs/building.md), or use --device cpu"
            ),
            Compute::Gpu => match first_gpu() {
                Some(device) => device,
                None => bail!(
                    "--device gpu: no CUDA GPU found (nprt loads the NVIDIA driver's libcuda at \
                     run time; this machine has {}); use --device cpu or auto",
                    if cuda_driver_present() {
                        "the driver but no device"
                    } else {
                        "no NVIDIA driver"
                    }
                ),
            },
            Compute::Wgpu if !cfg!(feature = "wgpu") => bail!(
                "--device wgpu: this nprt was built without wgpu support; rebuild it with \
                 `cargo build --release --features wgpu` (docs/building.md), or use --device cpu"
            ),
            Compute::Wgpu => match first_wgpu() {
                Some(device) => device,
                None => bail!(
                    "--device wgpu: no Vulkan or Metal adapter found (on Linux install a Vulkan \
                     driver; scripts/vulkan.sh installs Mesa's software one); use --device cpu"
                ),
            },
            Compute::Auto => first_gpu().unwrap_or_else(Device::flex),
        };
        make_default(&device);
        let mut used = GPUS_USED.lock().unwrap_or_else(|e| e.into_inner());
        if !is_cpu(&device) && !used.contains(&device) {
            used.push(device.clone());
        }
        Ok(device)
    }
}

/// Makes `device` burn's default device. burn materialises some state on its default device
/// (the optimiser's moments when a checkpoint is loaded), and that default is CUDA whenever
/// the CUDA backend is compiled in, GPU or not: without this a resumed CPU run on a machine
/// with no NVIDIA driver panicked. burn reads the choice from `BURN_DEVICE` on every use.
pub(crate) fn make_default(device: &Device) {
    let name = Backend::of(device).burn_name();
    if std::env::var("BURN_DEVICE").ok().as_deref() != Some(name) {
        std::env::set_var("BURN_DEVICE", name);
    }
}

/// Waits for the work queued on the GPU devices this process used. Called once a command is
/// done: work still running at exit ran after the driver had shut down, and panicked in burn's
/// device thread (CUDA, seen after resuming a run on an H100) or crashed inside the software
/// Vulkan driver's shader compiler (lavapipe, on most runs that compiled a kernel).
pub fn finish() {
    for device in GPUS_USED.lock().unwrap_or_else(|e| e.into_inner()).iter() {
        device.sync().ok();
    }
}

/// The GPU devices handed out by [`Compute::device`].
static GPUS_USED: std::sync::Mutex<Vec<Device>> = std::sync::Mutex::new(Vec::new());

/// The burn backend a device belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// flex, where the hand-written engine applies.
    Cpu,
    Cuda,
    Wgpu,
}

impl Backend {
    pub fn of(device: &Device) -> Self {
        if is_cpu(device) {
            Backend::Cpu
        } else if format!("{device:?}").contains("Wgpu") {
            // burn names the runtime only in its dispatch enum, which it does not re-export.
            Backend::Wgpu
        } else {
            Backend::Cuda
        }
    }

    /// The name in reports: "cpu", "cuda" or "wgpu".
    pub fn name(self) -> &'static str {
        match self {
            Backend::Cpu => "cpu",
            Backend::Cuda => "cuda",
            Backend::Wgpu => "wgpu",
        }
    }

    /// burn's name for it, what `BURN_DEVICE` takes.
    fn burn_name(self) -> &'static str {
        match self {
            Backend::Cpu => "flex",
            backend => backend.name(),
        }
    }
}

/// Whether `device` is the CPU (flex), where the hand-written engine applies.
pub fn is_cpu(device: &Device) -> bool {
    device.clone().inner() == Device::flex()
}

/// A short name for progress lines and reports: "cpu", or the backend and the device's own
/// name ("cuda: NVIDIA H100 PCIe", "wgpu: llvmpipe (LLVM 15.0.6, 256 bits)").
pub fn device_name(device: &Device) -> String {
    let backend = Backend::of(device);
    match gpu_name(device) {
        Some(name) => format!("{}: {name}", backend.name()),
        None => backend.name().into(),
    }
}

/// A GPU device's own name (none for the CPU).
#[cfg(any(feature = "cuda", feature = "wgpu"))]
fn gpu_name(device: &Device) -> Option<String> {
    (!is_cpu(device))
        .then(|| device.identity())
        .flatten()
        .map(|id| id.name.to_string())
}

/// Without a GPU backend every device is the CPU.
#[cfg(not(any(feature = "cuda", feature = "wgpu")))]
fn gpu_name(_: &Device) -> Option<String> {
    None
}

#[cfg(feature = "cuda")]
fn first_gpu() -> Option<Device> {
    Device::enumerate(burn::tensor::DeviceType::Cuda)
        .into_iter()
        .next()
}

#[cfg(not(feature = "cuda"))]
fn first_gpu() -> Option<Device> {
    None
}

#[cfg(feature = "wgpu")]
fn first_wgpu() -> Option<Device> {
    Device::enumerate(burn::tensor::DeviceType::Wgpu)
        .into_iter()
        .next()
}

#[cfg(not(feature = "wgpu"))]
fn first_wgpu() -> Option<Device> {
    None
}

fn cuda_driver_present() -> bool {
    ["libcuda.so.1", "libcuda.so"].iter().any(|name| {
        // SAFETY: loading the NVIDIA driver library runs no initialiser with preconditions.
        unsafe { libloading::Library::new(name) }.is_ok()
    })
}

/// A tensor's values as f32 on the host.
pub fn host_values(data: TensorData) -> Vec<f32> {
    data.convert::<f32>()
        .try_into_vec::<f32>()
        .expect("converted to f32")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_is_flex_and_auto_falls_back_without_a_gpu() {
        assert!(is_cpu(&Compute::Cpu.device().unwrap()));
        let gpu = Compute::Gpu.device();
        match &gpu {
            Ok(device) => assert!(!is_cpu(device)),
            Err(e) if cfg!(feature = "cuda") => {
                assert!(e.to_string().contains("no CUDA GPU found"), "{e}");
                assert!(is_cpu(&Compute::Auto.device().unwrap()));
            }
            Err(e) => {
                assert!(e.to_string().contains("built without CUDA support"), "{e}");
                assert!(is_cpu(&Compute::Auto.device().unwrap()));
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
