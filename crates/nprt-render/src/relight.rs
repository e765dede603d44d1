//! The run-time network: light code once per lighting change, transport on foreground pixels,
//! for a still camera the light-independent part (the transfer networks' ŝ) kept between
//! lighting changes, and for models that leave direct light to the tracer, that light traced.
//! A [`Relighter`] resolves the `--device` engine once into that engine's networks and frame
//! stages ([`OnEngine`], whose types keep each engine's light codes and pixels to it); this
//! file holds the model's side of a frame and picks the engine, `on_engine.rs` what a frame
//! does on it.

use std::path::Path;
use std::time::Instant;

use anyhow::Result;
use glam::Vec3;
use nprt_net::{load_model, CpuEngine, Engine, ModelFile, NetworkEngine, NprtNet, Shading};
use nprt_scene::{Camera, EnvMap};
use nprt_trace::{GBuffer, RenderSettings, TraceScene};

use crate::frame_stages::{DirectSampling, FrameRadiance, FrameStages, HostStages};
use crate::frame_timings::FrameTimings;
use crate::on_engine::{Kept, OnEngine};
use crate::Precision;

/// Samples per pixel of the traced direct light when none is asked for: the recommended
/// recipe's (on the demo, D/S with traced direct light beats equal-time path tracing in every
/// metric from 4 spp, by a margin that grows with the count; 16 takes most of it:
/// docs/model.md#traced-direct-light).
pub const DEFAULT_DIRECT_SPP: u32 = nprt_net::RECIPE.direct_spp;

/// The CPU engine's networks, beside the CPU tracer ([`HostStages`]).
type CpuNet = <CpuEngine as NetworkEngine>::Network;
type CpuFrames = OnEngine<CpuNet, HostStages>;

/// The GPU kernels' networks, beside the rasterised G-buffer and the tracer's kernels.
#[cfg(feature = "gpu")]
type GpuNet = <nprt_net::gpu::GpuKernels as NetworkEngine>::Network;
#[cfg(feature = "gpu")]
type GpuFrames = OnEngine<GpuNet, crate::gpu::DeviceStages>;

/// The engine a model's frames run on, resolved once (the GPU's boxed: its kernels' state is
/// most of the size).
enum Engines {
    Cpu(CpuFrames),
    #[cfg(feature = "gpu")]
    Gpu(Box<GpuFrames>),
}

/// Runs `$body` with `$e` bound to the engine's [`OnEngine`], whichever it is.
macro_rules! on_engine {
    ($engines:expr, $e:ident => $body:expr) => {
        match $engines {
            Engines::Cpu($e) => $body,
            #[cfg(feature = "gpu")]
            Engines::Gpu($e) => $body,
        }
    };
}

/// A trained model ready to shade G-buffers.
pub struct Relighter {
    pub file: ModelFile,
    /// The networks and the frame's other stages, on the engine the model was loaded for.
    engine: Engines,
}

/// What consecutive frames keep: the last camera's G-buffer and network inputs (with the
/// light-independent networks' outputs), and the last lighting's code under its key `K`, in
/// the types of the engine that made them (a cache from another engine holds nothing a frame
/// can use, and is replaced).
pub struct FrameCache<K> {
    kept: EngineCache<K>,
}

/// What the last frame kept, on the engine that made it.
enum EngineCache<K> {
    Empty,
    Cpu(Kept<CpuNet, HostStages, K>),
    #[cfg(feature = "gpu")]
    Gpu(Kept<GpuNet, crate::gpu::DeviceStages, K>),
}

impl<K> FrameCache<K> {
    /// Foreground pixels of the kept G-buffer (none before a frame).
    pub fn foreground(&self) -> usize {
        match &self.kept {
            EngineCache::Empty => 0,
            EngineCache::Cpu(kept) => kept.foreground(),
            #[cfg(feature = "gpu")]
            EngineCache::Gpu(kept) => kept.foreground(),
        }
    }
}

impl<K> Default for FrameCache<K> {
    fn default() -> Self {
        FrameCache {
            kept: EngineCache::Empty,
        }
    }
}

/// A G-buffer's pixels and a lighting made ready by a model's networks: relighting runs only
/// what depends on the lighting ([`Relighter::still`]).
pub struct Still<'a> {
    relight: Box<dyn Fn() -> Vec<Vec3> + 'a>,
}

impl Still<'_> {
    /// Radiance of every pixel; background pixels are zero.
    pub fn relight(&self) -> Vec<Vec3> {
        (self.relight)()
    }
}

impl Relighter {
    /// Loads the model in `dir` to run on `engine`.
    pub fn load(dir: &Path, engine: Engine) -> Result<Self> {
        let (file, net) = load_model(dir)?;
        Self::new(file, net, engine)
    }

    /// A model with `file`'s settings and the weights of `net` (on the host), to run on
    /// `engine`: the one place a frame's networks and stages choose between the CPU engine and
    /// the GPU kernels.
    pub fn new(file: ModelFile, net: NprtNet, engine: Engine) -> Result<Self> {
        let engine = match engine {
            Engine::Cpu => Engines::Cpu(OnEngine {
                net: CpuEngine::network(&file, net)?,
                stages: HostStages,
            }),
            #[cfg(feature = "gpu")]
            Engine::Gpu => Engines::Gpu(Box::new(OnEngine {
                net: nprt_net::gpu::GpuKernels::network(&file, net)?,
                stages: crate::gpu::DeviceStages::default(),
            })),
            #[cfg(not(feature = "gpu"))]
            Engine::Gpu => anyhow::bail!("this nprt-render was built without its GPU kernels"),
        };
        Ok(Relighter { file, engine })
    }

    /// Takes `file`'s settings and `net`'s weights (a run's newer model), in the precision the
    /// networks ran in, on the engine they ran on; the G-buffer and traced light stay as they
    /// are. Frames made after use them, with a new [`FrameCache`].
    pub fn set_weights(&mut self, file: ModelFile, net: NprtNet) -> Result<()> {
        let precision = self.precision();
        match &mut self.engine {
            Engines::Cpu(e) => e.net = CpuEngine::network(&file, net)?,
            #[cfg(feature = "gpu")]
            Engines::Gpu(e) => e.net = nprt_net::gpu::GpuKernels::network(&file, net)?,
        }
        self.set_precision(precision)?;
        self.file = file;
        Ok(())
    }

    /// Runs the networks in `precision`; f16 needs the GPU kernels (`--device gpu`) and an
    /// adapter with f16 in shaders. Frames made after use it, with a new [`FrameCache`].
    pub fn set_precision(&mut self, precision: Precision) -> Result<()> {
        on_engine!(&mut self.engine, e => e.net.set_precision(precision))
    }

    /// The precision the networks run in.
    pub fn precision(&self) -> Precision {
        on_engine!(&self.engine, e => e.net.precision())
    }

    /// Where the networks run, for reports: "CPU engine" or "GPU kernels on ADAPTER".
    pub fn networks_on(&self) -> String {
        on_engine!(&self.engine, e => e.net.describe())
    }

    /// Where the G-buffer is made, for reports: rasterised beside the GPU kernels, or the CPU
    /// tracer's primary rays.
    pub fn gbuffer_on(&self) -> &'static str {
        on_engine!(&self.engine, e => e.stages.gbuffer_on())
    }

    /// Where [`Self::path_trace`] and traced direct light run, for reports.
    pub fn paths_on(&self) -> &'static str {
        on_engine!(&self.engine, e => e.stages.paths_on())
    }

    /// What runs, in one line for each command to print: "linear design on sh:2 (siren),
    /// direct light traced (16 spp, denoised by OIDN), level calibrated".
    pub fn describe(&self, sampling: &DirectSampling) -> String {
        let denoised = match sampling.denoiser {
            Some(_) => "denoised by OIDN",
            None => "not denoised",
        };
        (self.file).describe(&format!("{} spp, {denoised}", sampling.spp))
    }

    /// Whether the model leaves direct light to the tracer ([`Self::complete`] traces it).
    pub fn traces_direct(&self) -> bool {
        !self.file.config.direct.is_learned()
    }

    /// Completes a frame the network shaded (`rgb`, background pixels zero) from G-buffer `g`
    /// under `map` (the lighting as placed in the world): for a model that traces direct light,
    /// adds every pixel's direct light, traced through the pixel centre as `sampling` says (on
    /// background pixels that is the map itself); otherwise fills background pixels with the
    /// map.
    pub fn complete(
        &self,
        ts: &TraceScene,
        camera: &Camera,
        map: &EnvMap,
        g: &GBuffer,
        sampling: DirectSampling,
        rgb: &mut [Vec3],
    ) -> Result<()> {
        let file = &self.file;
        on_engine!(&self.engine, e => e.complete(file, ts, camera, map, g, sampling, rgb))
    }

    /// One frame through `camera` under `map` turned by `rotation_deg` (the lighting `key`
    /// names): the G-buffer and the light-independent networks only when the camera moved
    /// since the frame `cache` holds, the encoder only when the key changed, then the shading
    /// networks and [`Self::complete`] (where the G-buffer stayed on the device, the whole
    /// frame there, its background included). Returns the radiance and each stage's time.
    #[allow(clippy::too_many_arguments)]
    pub fn frame<K: PartialEq>(
        &self,
        cache: &mut FrameCache<K>,
        ts: &TraceScene,
        camera: &Camera,
        map: &EnvMap,
        rotation_deg: f32,
        key: K,
        sampling: DirectSampling,
    ) -> Result<(Vec<Vec3>, FrameTimings)> {
        let lit = (map, rotation_deg, key);
        let (shown, t) = self.frame_shown(cache, ts, camera, lit, sampling, false)?;
        Ok((shown.into_host(), t))
    }

    /// [`Self::frame`], its radiance left on the device where the whole frame was made there
    /// and `keep` asks (what `nprt view` shows), read back otherwise.
    pub fn frame_shown<K: PartialEq>(
        &self,
        cache: &mut FrameCache<K>,
        ts: &TraceScene,
        camera: &Camera,
        lit: (&EnvMap, f32, K),
        sampling: DirectSampling,
        keep: bool,
    ) -> Result<(FrameRadiance, FrameTimings)> {
        let file = &self.file;
        let kept = std::mem::replace(&mut cache.kept, EngineCache::Empty);
        match &self.engine {
            Engines::Cpu(e) => {
                let mut kept = match kept {
                    EngineCache::Cpu(kept) => kept,
                    _ => Kept::default(),
                };
                let shown = e.frame_shown(file, &mut kept, ts, camera, lit, sampling, keep);
                cache.kept = EngineCache::Cpu(kept);
                shown
            }
            #[cfg(feature = "gpu")]
            Engines::Gpu(e) => {
                let mut kept = match kept {
                    EngineCache::Gpu(kept) => kept,
                    _ => Kept::default(),
                };
                let shown = e.frame_shown(file, &mut kept, ts, camera, lit, sampling, keep);
                cache.kept = EngineCache::Gpu(kept);
                shown
            }
        }
    }

    /// The G-buffer of `camera`'s pixel centres: rasterised on the GPU beside the kernels (the
    /// scene uploaded at its first frame), traced otherwise.
    pub fn gbuffer(&self, ts: &TraceScene, camera: &Camera) -> Result<GBuffer> {
        on_engine!(&self.engine, e => e.stages.gbuffer(ts, camera))
    }

    /// One pass of path tracing of `camera`'s view under `map` (as placed in the world), as
    /// `settings` says, on the device this model's frames are made on.
    pub fn path_trace(
        &self,
        ts: &TraceScene,
        camera: &Camera,
        map: &EnvMap,
        settings: &RenderSettings,
    ) -> Result<Vec<Vec3>> {
        on_engine!(&self.engine, e => e.stages.path_trace(ts, camera, map, settings))
    }

    /// The GPU time of each kernel of a lighting change of the pixels `cache` keeps, under the
    /// lighting it keeps (`nprt bench frame --profile`). None off the GPU kernels or before a
    /// frame.
    #[cfg(feature = "gpu")]
    pub fn profile_relight<K>(
        &self,
        cache: &FrameCache<K>,
    ) -> Result<Option<Vec<nprt_gpu::KernelTime>>> {
        match (&self.engine, &cache.kept) {
            (Engines::Gpu(e), EngineCache::Gpu(kept)) => e.profile_relight(kept),
            _ => Ok(None),
        }
    }

    /// How many times the host has waited for the GPU kernels' queue so far (None off them):
    /// `nprt bench frame` counts a lighting change's.
    pub fn host_waits(&self) -> Option<u64> {
        on_engine!(&self.engine, e => e.net.host_waits())
    }

    /// Radiance of every pixel of `g` under `map` turned by `rotation_deg`, background pixels
    /// zero (see [`background`]), with the encoder's time (its queue waited for) and the
    /// networks'.
    pub fn shade(
        &self,
        g: &GBuffer,
        (map, rotation_deg): (&EnvMap, f32),
    ) -> Result<(Vec<Vec3>, FrameTimings)> {
        let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
        let bounds = &self.file.bounds;
        on_engine!(&self.engine, e => {
            let clock = Instant::now();
            let code = Shading::light_code(&e.net, map, rotation_deg);
            e.net.settle()?;
            let encoder_ms = ms(clock);
            let clock = Instant::now();
            let rgb = e.relight(&e.foreground(bounds, g), &code);
            let t = FrameTimings {
                encoder_ms,
                network_ms: ms(clock),
                ..FrameTimings::default()
            };
            Ok((rgb, t))
        })
    }

    /// `g`'s foreground pixels through what of the networks does not depend on the lighting,
    /// and the light code of `map` turned by `rotation_deg`: each [`Still::relight`] then runs
    /// only the shading networks.
    pub fn still<'a>(&'a self, g: &GBuffer, map: &EnvMap, rotation_deg: f32) -> Still<'a> {
        let bounds = &self.file.bounds;
        let relight: Box<dyn Fn() -> Vec<Vec3> + 'a> = on_engine!(&self.engine, e => {
            let (px, code) = (e.foreground(bounds, g), Shading::light_code(&e.net, map, rotation_deg));
            Box::new(move || e.relight(&px, &code))
        });
        Still { relight }
    }

    /// Floating-point operations of the dense layers per foreground pixel, for a frame from a
    /// new viewpoint or (`transfer_known`) a lighting change under a still camera; None off the
    /// CPU engine.
    pub fn flops_per_pixel(&self, transfer_known: bool) -> Option<f64> {
        on_engine!(&self.engine, e => e.net.flops_per_pixel(transfer_known))
    }
}
