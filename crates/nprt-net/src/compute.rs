//! Where the networks run: the `--device` choice of every command that trains or infers, and
//! the one place that turns it into a burn [`Device`]. Model code never asks; it runs on the
//! device its tensors live on, so a model folder is the same whichever trained it.

use anyhow::{bail, Result};
use burn::tensor::{Device, DeviceType};

/// `--device`: the CPU, an NVIDIA GPU through CUDA, or the GPU when one is present.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Compute {
    Cpu,
    Gpu,
    #[default]
    Auto,
}

impl Compute {
    pub fn name(self) -> &'static str {
        match self {
            Compute::Cpu => "cpu",
            Compute::Gpu => "gpu",
            Compute::Auto => "auto",
        }
    }

    /// The device to run on. `gpu` without a usable CUDA device is an error naming what is
    /// missing; `auto` then falls back to the CPU.
    /// The chosen device also becomes burn's default (see [`make_default`]).
    pub fn device(self) -> Result<Device> {
        let device = match self {
            Compute::Cpu => Device::flex(),
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
            Compute::Auto => first_gpu().unwrap_or_else(Device::flex),
        };
        make_default(&device);
        Ok(device)
    }
}

/// Makes `device` burn's default device. burn materialises some state on its default device
/// (the optimiser's moments when a checkpoint is loaded), and that default is CUDA whenever
/// the CUDA backend is compiled in, GPU or not: without this a resumed CPU run on a machine
/// with no NVIDIA driver panicked. burn reads the choice from `BURN_DEVICE` on every use.
pub(crate) fn make_default(device: &Device) {
    let name = if is_cpu(device) { "flex" } else { "cuda" };
    if std::env::var("BURN_DEVICE").ok().as_deref() != Some(name) {
        std::env::set_var("BURN_DEVICE", name);
    }
}

/// Waits for the work queued on burn's default device when that is a GPU. Called once a
/// command is done: work still queued at exit ran after the CUDA driver had shut down and
/// panicked in burn's device thread (seen after resuming a run on an H100).
pub fn finish() {
    if std::env::var("BURN_DEVICE").ok().as_deref() == Some("cuda") {
        Device::default().sync().ok();
    }
}

/// Whether `device` is the CPU (flex), where the hand-written engine applies.
pub fn is_cpu(device: &Device) -> bool {
    device.clone().inner() == Device::flex()
}

/// A short name for progress lines and reports: "cpu" or "cuda:N".
pub fn device_name(device: &Device) -> String {
    if is_cpu(device) {
        "cpu".into()
    } else {
        format!("{device:?}")
    }
}

fn first_gpu() -> Option<Device> {
    Device::enumerate(DeviceType::Cuda).into_iter().next()
}

fn cuda_driver_present() -> bool {
    ["libcuda.so.1", "libcuda.so"].iter().any(|name| {
        // SAFETY: loading the NVIDIA driver library runs no initialiser with preconditions.
        unsafe { libloading::Library::new(name) }.is_ok()
    })
}

impl std::str::FromStr for Compute {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "cpu" => Ok(Compute::Cpu),
            "gpu" => Ok(Compute::Gpu),
            "auto" => Ok(Compute::Auto),
            _ => Err(format!("unknown device '{s}' (expected cpu, gpu or auto)")),
        }
    }
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
            Err(e) => {
                assert!(e.to_string().contains("no CUDA GPU found"), "{e}");
                assert!(is_cpu(&Compute::Auto.device().unwrap()));
            }
        }
        assert_eq!("gpu".parse::<Compute>(), Ok(Compute::Gpu));
        assert!("tpu"
            .parse::<Compute>()
            .unwrap_err()
            .contains("cpu, gpu or auto"));
    }
}
