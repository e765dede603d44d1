//! Where frames are path traced: the CPU tracer, or (feature `gpu`) the same tracer on the
//! GPU ([`crate::gpu`]). Both estimate the same image; they draw different random numbers, so
//! a dataset records which made it.

use anyhow::Result;
use nprt_scene::{Camera, EnvMap};
use serde::{Deserialize, Serialize};

use crate::{render, Frame, RenderSettings, TraceScene};

/// Which tracer renders: what a dataset's manifest records and `nprt generate --device`
/// chooses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TraceDevice {
    #[default]
    Cpu,
    Gpu,
}

impl TraceDevice {
    pub fn is_cpu(&self) -> bool {
        *self == TraceDevice::Cpu
    }

    /// Refuses a `width` × `height` frame (`what`) this device cannot make, before any work:
    /// one the machine's memory cannot hold ([`Frame::check_size`]) or, on the GPU, one with a
    /// side past the largest texture it rasterises (wgpu would panic on it). Every command
    /// calls it where it chooses a frame size.
    pub fn check_frame(&self, width: u32, height: u32, what: &str) -> Result<()> {
        Frame::check_size(width, height, what)?;
        #[cfg(feature = "gpu")]
        if *self == TraceDevice::Gpu {
            nprt_gpu::GpuDevice::get()?.check_frame(width, height, what)?;
        }
        Ok(())
    }
}

/// A scene ready to trace on one device: on the GPU, uploaded once for every frame.
pub enum Tracer<'a> {
    Cpu(&'a TraceScene<'a>),
    #[cfg(feature = "gpu")]
    Gpu(Box<crate::gpu::RasterGBuffer>),
}

impl<'a> Tracer<'a> {
    /// `ts` ready to trace on `device`: an error where the GPU does not open, or in a build
    /// without the GPU tracer.
    pub fn new(device: TraceDevice, ts: &'a TraceScene<'a>) -> Result<Self> {
        match device {
            TraceDevice::Cpu => Ok(Tracer::Cpu(ts)),
            #[cfg(feature = "gpu")]
            TraceDevice::Gpu => Ok(Tracer::Gpu(Box::new(crate::gpu::RasterGBuffer::new(ts)?))),
            #[cfg(not(feature = "gpu"))]
            TraceDevice::Gpu => anyhow::bail!(
                "this nprt was built without its GPU tracer; rebuild it with `cargo build \
                 --release --features gpu` (docs/building.md), or use --device cpu"
            ),
        }
    }

    /// The device this tracer runs on.
    pub fn device(&self) -> TraceDevice {
        match self {
            Tracer::Cpu(_) => TraceDevice::Cpu,
            #[cfg(feature = "gpu")]
            Tracer::Gpu(_) => TraceDevice::Gpu,
        }
    }

    /// The scene as the CPU tracer holds it (None on the GPU), for what only it records.
    pub fn cpu_scene(&self) -> Option<&TraceScene<'a>> {
        match self {
            Tracer::Cpu(ts) => Some(ts),
            #[cfg(feature = "gpu")]
            Tracer::Gpu(_) => None,
        }
    }

    /// A frame of `camera` under `env` as [`render`] makes it with `settings`.
    pub fn render(
        &self,
        camera: &Camera,
        env: &EnvMap,
        settings: &RenderSettings,
    ) -> Result<Frame> {
        nprt_io::interrupt::check()?;
        match self {
            Tracer::Cpu(ts) => {
                let frame = render(ts, camera, env, settings);
                // Rows skipped by a stop request: not a frame to keep.
                nprt_io::interrupt::check()?;
                Ok(frame)
            }
            #[cfg(feature = "gpu")]
            Tracer::Gpu(raster) => raster.render_frame(camera, env, settings),
        }
    }
}
