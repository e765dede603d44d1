//! A frame's stages besides the networks, on the device the networks run on: the G-buffer,
//! traced light (direct light for models that leave it to the tracer, and whole paths), and,
//! where the G-buffer can stay on the device, the frame made there from G-buffer to background.
//! The CPU's ([`HostStages`]: nprt-trace's tracer, beside any engine's networks) and the GPU's
//! (`gpu::DeviceStages`: rasterised G-buffers and the tracer's kernels, beside the GPU
//! kernels' networks) implement [`FrameStages`], and [`KeptStages`] for the networks they run
//! beside, which the types hold them to: pixels they keep, and light codes they are given, are
//! that network's.

use std::convert::Infallible;

use anyhow::Result;
use glam::{Vec2, Vec3};
use nprt_net::Shading;
use nprt_scene::{Camera, EnvMap};
use nprt_trace::{render, render_direct, render_gbuffer, GBuffer, RenderSettings, TraceScene};
use rayon::prelude::*;

use crate::oidn::Oidn;

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

/// A camera's pixels whose G-buffer stayed on the device, as [`KeptStages::kept_pixels`]
/// made them: a row per pixel, and the milliseconds of the G-buffer and of the networks.
pub struct KeptPixels<R> {
    pub rows: R,
    pub gbuffer_ms: f64,
    pub network_ms: f64,
}

/// How a frame's direct light is traced, for a model that leaves it to the tracer.
#[derive(Clone, Copy)]
pub struct DirectSampling {
    /// Samples per pixel, each a shadow ray towards the importance-sampled map and a BSDF
    /// sample combined by MIS.
    pub spp: u32,
    pub seed: u64,
    /// Denoises the traced light (with the G-buffer as auxiliaries) before it is added.
    pub denoiser: Option<&'static Oidn>,
}

/// The traced direct light of a frame: samples per pixel and seed.
pub type DirectRays = (u32, u64);

/// A camera's pixels as an engine holds them: the foreground's rows on the networks, or every
/// pixel of a G-buffer the stages kept on the device.
pub enum Rows<R, K> {
    Networks(R),
    Kept(K),
}

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

    /// Where the G-buffer is made, for reports.
    fn gbuffer_on(&self) -> &'static str;

    /// Where traced light runs, for reports.
    fn paths_on(&self) -> &'static str;
}

/// The stages beside the networks `N`, where a G-buffer can stay on the device and the frame
/// be finished there.
pub trait KeptStages<N: Shading>: FrameStages {
    /// A camera's pixels with their G-buffer kept on the device ([`Self::kept_pixels`]).
    type Kept: Send + Sync;

    /// `camera`'s pixels with the G-buffer left on the device and run through `shading`'s
    /// light-independent part there (positions normalised by `bounds`); None where G-buffers
    /// are made on the host.
    fn kept_pixels(
        &self,
        shading: &N,
        ts: &TraceScene,
        camera: &Camera,
        bounds: &[[f32; 3]; 2],
    ) -> Result<Option<KeptPixels<Self::Kept>>>;

    /// The finished frame of [`Self::kept_pixels`]' rows under `light`, with `map` (as placed
    /// in the world) behind or, with `direct`, that light traced over every pixel; left on the
    /// device where `keep` asks, read back otherwise. With the milliseconds of the traced light.
    #[allow(clippy::too_many_arguments)]
    fn kept_frame(
        &self,
        shading: &N,
        ts: &TraceScene,
        rows: &Self::Kept,
        light: &N::Code,
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
        shading: &N,
        rows: Rows<&N::Rows, &Self::Kept>,
        light: &N::Code,
    ) -> Result<Vec<nprt_gpu::KernelTime>>;
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

    fn gbuffer_on(&self) -> &'static str {
        "traced on the CPU"
    }

    fn paths_on(&self) -> &'static str {
        "on the CPU"
    }
}

impl<N: Shading> KeptStages<N> for HostStages {
    type Kept = Infallible;

    fn kept_pixels(
        &self,
        _: &N,
        _: &TraceScene,
        _: &Camera,
        _: &[[f32; 3]; 2],
    ) -> Result<Option<KeptPixels<Infallible>>> {
        Ok(None)
    }

    fn kept_frame(
        &self,
        _: &N,
        _: &TraceScene,
        rows: &Infallible,
        _: &N::Code,
        _: &EnvMap,
        _: Option<DirectRays>,
        _: bool,
    ) -> Result<(FrameRadiance, f64)> {
        match *rows {}
    }

    #[cfg(feature = "gpu")]
    fn profile(
        &self,
        _: &N,
        _: Rows<&N::Rows, &Infallible>,
        _: &N::Code,
    ) -> Result<Vec<nprt_gpu::KernelTime>> {
        anyhow::bail!("kernel times are measured on the GPU kernels only (--device gpu)")
    }
}

/// Fills background pixels (mask 0) with the map seen through the pixel centre.
pub fn background(camera: &Camera, map: &EnvMap, mask: &[f32], rgb: &mut [Vec3]) {
    let w = camera.width as usize;
    rgb.par_iter_mut().enumerate().for_each(|(i, c)| {
        if mask[i] <= 0.5 {
            let (_, d) = camera.ray(Vec2::new((i % w) as f32 + 0.5, (i / w) as f32 + 0.5));
            *c = map.eval(d);
        }
    });
}
