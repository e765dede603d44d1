//! A frame's stages besides the networks, on the device the networks run on: the G-buffer,
//! traced light (direct light for models that leave it to the tracer, and whole paths), and,
//! where the G-buffer can stay on the device, the frame made there from G-buffer to background.
//! The CPU's ([`HostStages`]: nprt-trace's tracer) and the GPU's (`gpu::DeviceStages`:
//! rasterised G-buffers and the tracer's kernels) implement one trait, chosen once by
//! [`frame_stages`] beside the networks' engine.

use anyhow::Result;
use glam::Vec3;
use nprt_net::{Engine, LightCode, PixelRows, Shading};
use nprt_scene::{Camera, EnvMap};
use nprt_trace::{render, render_direct, render_gbuffer, GBuffer, RenderSettings, TraceScene};

/// A frame's radiance, 3 f32 a pixel in pixel order: on the host, or left on the device by
/// the GPU kernels (`Relighter::frame_shown`).
pub enum FrameRadiance {
    Host(Vec<Vec3>),
    #[cfg(feature = "gpu")]
    Device {
        rgb: wgpu::Buffer,
        pixels: usize,
    },
}

impl FrameRadiance {
    /// The radiance on the host, read back from the device if it is there.
    pub fn into_host(self) -> Vec<Vec3> {
        match self {
            FrameRadiance::Host(rgb) => rgb,
            #[cfg(feature = "gpu")]
            FrameRadiance::Device { rgb, pixels } => {
                let gpu = nprt_gpu::GpuDevice::get().expect("a frame on the device has one");
                let rgb = gpu.read(&rgb, 3 * pixels);
                rgb.chunks_exact(3).map(Vec3::from_slice).collect()
            }
        }
    }
}

/// A camera's pixels whose G-buffer stayed on the device, as [`FrameStages::kept_pixels`]
/// made them: a row per pixel, and the milliseconds of the G-buffer and of the networks.
pub struct KeptPixels {
    pub rows: PixelRows,
    pub gbuffer_ms: f64,
    pub network_ms: f64,
}

/// The traced direct light of a frame: samples per pixel and seed.
pub type DirectRays = (u32, u64);

/// Where a frame's stages other than the networks run.
pub trait FrameStages: Send + Sync {
    /// The G-buffer of `camera`'s pixel centres.
    fn gbuffer(&self, ts: &TraceScene, camera: &Camera) -> Result<GBuffer>;

    /// Every pixel's direct light through its centre under `map` (as placed in the world),
    /// traced with `rays`.
    fn traced_direct(
        &self,
        ts: &TraceScene,
        camera: &Camera,
        map: &EnvMap,
        rays: DirectRays,
    ) -> Result<Vec<Vec3>>;

    /// One pass of path tracing of `camera`'s view under `map`, as `settings` says.
    fn path_trace(
        &self,
        ts: &TraceScene,
        camera: &Camera,
        map: &EnvMap,
        settings: &RenderSettings,
    ) -> Result<Vec<Vec3>>;

    /// `camera`'s pixels with the G-buffer left on the device and run through `shading`'s
    /// light-independent part there (positions normalised by `bounds`); None where G-buffers
    /// are made on the host.
    fn kept_pixels(
        &self,
        shading: &dyn Shading,
        ts: &TraceScene,
        camera: &Camera,
        bounds: &[[f32; 3]; 2],
    ) -> Result<Option<KeptPixels>>;

    /// The finished frame of [`Self::kept_pixels`]' rows under `light`, with `map` (as placed
    /// in the world) behind or, with `direct`, that light traced over every pixel; left on the
    /// device where `keep` asks, read back otherwise. With the milliseconds of the traced light.
    #[allow(clippy::too_many_arguments)]
    fn kept_frame(
        &self,
        shading: &dyn Shading,
        ts: &TraceScene,
        rows: &PixelRows,
        light: &LightCode,
        map: &EnvMap,
        direct: Option<DirectRays>,
        keep: bool,
    ) -> Result<(FrameRadiance, f64)>;

    /// The GPU time of each kernel of a lighting change of `rows` (made by
    /// [`Self::kept_pixels`] or by `shading`) under `light`, each dispatch timed in a pass of
    /// its own (`nprt bench frame --profile`).
    #[cfg(feature = "gpu")]
    fn profile(
        &self,
        shading: &dyn Shading,
        rows: &PixelRows,
        light: &LightCode,
    ) -> Result<Vec<nprt_gpu::KernelTime>>;

    /// Where the G-buffer is made, for reports.
    fn gbuffer_on(&self) -> &'static str;

    /// Where traced light runs, for reports.
    fn paths_on(&self) -> &'static str;
}

/// The stages beside the networks on `engine`.
pub fn frame_stages(engine: Engine) -> Result<Box<dyn FrameStages>> {
    match engine {
        Engine::Cpu => Ok(Box::new(HostStages)),
        #[cfg(feature = "gpu")]
        Engine::Gpu => Ok(Box::new(crate::gpu::DeviceStages::default())),
        #[cfg(not(feature = "gpu"))]
        Engine::Gpu => anyhow::bail!("this nprt-render was built without its GPU kernels"),
    }
}

/// The stages on the CPU: nprt-trace's tracer, every G-buffer on the host.
pub struct HostStages;

impl FrameStages for HostStages {
    fn gbuffer(&self, ts: &TraceScene, camera: &Camera) -> Result<GBuffer> {
        Ok(render_gbuffer(ts, camera))
    }

    fn traced_direct(
        &self,
        ts: &TraceScene,
        camera: &Camera,
        map: &EnvMap,
        (spp, seed): DirectRays,
    ) -> Result<Vec<Vec3>> {
        Ok(render_direct(ts, camera, map, spp, seed))
    }

    fn path_trace(
        &self,
        ts: &TraceScene,
        camera: &Camera,
        map: &EnvMap,
        settings: &RenderSettings,
    ) -> Result<Vec<Vec3>> {
        Ok(render(ts, camera, map, settings).radiance)
    }

    fn kept_pixels(
        &self,
        _: &dyn Shading,
        _: &TraceScene,
        _: &Camera,
        _: &[[f32; 3]; 2],
    ) -> Result<Option<KeptPixels>> {
        Ok(None)
    }

    fn kept_frame(
        &self,
        _: &dyn Shading,
        _: &TraceScene,
        _: &PixelRows,
        _: &LightCode,
        _: &EnvMap,
        _: Option<DirectRays>,
        _: bool,
    ) -> Result<(FrameRadiance, f64)> {
        unreachable!("the CPU's stages keep no pixels on a device")
    }

    #[cfg(feature = "gpu")]
    fn profile(
        &self,
        _: &dyn Shading,
        _: &PixelRows,
        _: &LightCode,
    ) -> Result<Vec<nprt_gpu::KernelTime>> {
        anyhow::bail!("kernel times are measured on the GPU kernels only (--device gpu)")
    }

    fn gbuffer_on(&self) -> &'static str {
        "traced on the CPU"
    }

    fn paths_on(&self) -> &'static str {
        "on the CPU"
    }
}
