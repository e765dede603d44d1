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
    pub fn device(self) -> Result<Device> {
        match self {
            Compute::Cpu => Ok(Device::flex()),
            Compute::Gpu => match first_gpu() {
                Some(device) => Ok(device),
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
            Compute::Auto => Ok(first_gpu().unwrap_or_else(Device::flex)),
        }
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
