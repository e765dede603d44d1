//! The run-time network: light code once per lighting change, transport on foreground pixels,
//! for a still camera the light-independent part (the transfer networks' ŝ) kept between
//! lighting changes, and for models that leave direct light to the tracer, that light traced.
//! The networks run on an engine's [`Shading`], the other stages on its [`FrameStages`]; this
//! file holds what a frame does with them, whichever the engine.

use std::path::Path;
use std::time::Instant;

use anyhow::Result;
use glam::{Vec2, Vec3};
use nprt_net::{
    gbuffer_features, load_model, DirectLight, Engine, LightCode, ModelFile, NprtNet, PixelRows,
    Shading, FEATURES,
};
use nprt_scene::{Camera, EnvMap};
use nprt_trace::{GBuffer, RenderSettings, TraceScene};
use rayon::prelude::*;

use crate::frame_stages::{frame_stages, FrameRadiance, FrameStages, KeptPixels};
use crate::frame_timings::FrameTimings;
use crate::oidn::Oidn;
use crate::Precision;

/// Samples per pixel of the traced direct light when none is asked for: the recommended
/// recipe's (on the demo, D/S with traced direct light beats equal-time path tracing in every
/// metric from 4 spp, by a margin that grows with the count; 16 takes most of it:
/// docs/model.md#traced-direct-light).
pub const DEFAULT_DIRECT_SPP: u32 = nprt_net::RECIPE.direct_spp;

/// A trained model ready to shade G-buffers.
pub struct Relighter {
    pub file: ModelFile,
    /// The networks, on the engine the model was loaded for.
    shading: Box<dyn Shading>,
    /// The G-buffer and traced light, beside them.
    stages: Box<dyn FrameStages>,
}

/// A G-buffer's foreground pixels as the networks hold them, with what of the networks does
/// not depend on the lighting: all a still camera needs to relight.
pub struct Pixels {
    count: usize,
    foreground: Vec<usize>,
    rows: PixelRows,
    /// Whether the G-buffer stayed on the device ([`FrameStages::kept_pixels`]): every pixel
    /// then has a row, and the frame is finished there.
    kept: bool,
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

/// What consecutive frames keep: the last camera's G-buffer and network inputs (with the
/// light-independent networks' outputs), and the last lighting's code under its key `K`.
pub struct FrameCache<K> {
    still: Option<(Camera, GBuffer, Pixels)>,
    light: Option<(K, LightCode)>,
}

impl<K> FrameCache<K> {
    /// Foreground pixels of the kept G-buffer (none before a frame).
    pub fn foreground(&self) -> usize {
        self.still
            .as_ref()
            .map_or(0, |(_, _, px)| px.foreground.len())
    }
}

impl<K> Default for FrameCache<K> {
    fn default() -> Self {
        FrameCache {
            still: None,
            light: None,
        }
    }
}

impl Relighter {
    /// Loads the model in `dir` to run on `engine`.
    pub fn load(dir: &Path, engine: Engine) -> Result<Self> {
        let (file, net) = load_model(dir)?;
        Self::new(file, net, engine)
    }

    /// A model with `file`'s settings and the weights of `net` (on the host), to run on
    /// `engine`.
    pub fn new(file: ModelFile, net: NprtNet, engine: Engine) -> Result<Self> {
        Ok(Relighter {
            shading: engine.network(&file, net)?,
            stages: frame_stages(engine)?,
            file,
        })
    }

    /// Takes `file`'s settings and `net`'s weights (a run's newer model) on `engine`, in the
    /// precision the networks ran in; the G-buffer and traced light stay as they are. Frames
    /// made after use them, with a new [`FrameCache`].
    pub fn set_weights(&mut self, file: ModelFile, net: NprtNet, engine: Engine) -> Result<()> {
        let precision = self.precision();
        self.shading = engine.network(&file, net)?;
        self.shading.set_precision(precision)?;
        self.file = file;
        Ok(())
    }

    /// Runs the networks in `precision`; f16 needs the GPU kernels (`--device gpu`) and an
    /// adapter with f16 in shaders. Frames made after use it, with a new [`FrameCache`].
    pub fn set_precision(&mut self, precision: Precision) -> Result<()> {
        self.shading.set_precision(precision)
    }

    /// The precision the networks run in.
    pub fn precision(&self) -> Precision {
        self.shading.precision()
    }

    /// Where the networks run, for reports: "CPU engine" or "GPU kernels on ADAPTER".
    pub fn networks_on(&self) -> String {
        self.shading.describe()
    }

    /// Where the G-buffer is made, for reports: rasterised beside the GPU kernels, or the CPU
    /// tracer's primary rays.
    pub fn gbuffer_on(&self) -> &'static str {
        self.stages.gbuffer_on()
    }

    /// Where [`Self::path_trace`] and traced direct light run, for reports.
    pub fn paths_on(&self) -> &'static str {
        self.stages.paths_on()
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
        self.file.config.direct == DirectLight::Traced
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
        if !self.traces_direct() {
            background(camera, map, &g.mask, rgb);
            return Ok(());
        }
        let rays = (sampling.spp, sampling.seed);
        let mut direct = self.stages.traced_direct(ts, camera, map, rays)?;
        if let Some(oidn) = sampling.denoiser {
            let (w, h) = (camera.width as usize, camera.height as usize);
            direct = oidn.denoise_frame(&direct, g, w, h)?;
        }
        rgb.par_iter_mut().zip(direct).for_each(|(c, d)| *c += d);
        Ok(())
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
        (map, rotation_deg, key): (&EnvMap, f32, K),
        sampling: DirectSampling,
        keep: bool,
    ) -> Result<(FrameRadiance, FrameTimings)> {
        let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
        let mut t = FrameTimings::default();
        let moved = !matches!(&cache.still, Some((c, _, _)) if c == camera);
        let code = match cache.light.take() {
            Some((k, code)) if k == key => code,
            _ => {
                let clock = Instant::now();
                let code = self.light_code(map, rotation_deg);
                // On the GPU kernels the code is only queued: before a new viewpoint's stages,
                // which wait for the queue one by one, it is waited for, so that the G-buffer
                // is not charged with it. A lighting change alone does not wait.
                if moved {
                    self.settle()?;
                }
                t.encoder_ms = ms(clock);
                code
            }
        };
        let (g, px) = match cache.still.take() {
            Some((c, g, px)) if c == *camera => (g, px),
            _ => match self.kept_pixels(ts, camera, &sampling, &mut t)? {
                Some(px) => (GBuffer::default(), px),
                None => {
                    let clock = Instant::now();
                    let g = self.gbuffer(ts, camera)?;
                    t.gbuffer_ms = ms(clock);
                    let clock = Instant::now();
                    let px = self.pixels(&g);
                    t.network_ms = ms(clock);
                    (g, px)
                }
            },
        };
        let placed = map.rotated_y(rotation_deg);
        let clock = Instant::now();
        let shown = if px.kept {
            let direct = self
                .traces_direct()
                .then_some((sampling.spp, sampling.seed));
            let shading = &*self.shading;
            let (shown, direct_ms) =
                (self.stages).kept_frame(shading, ts, &px.rows, &code, &placed, direct, keep)?;
            t.network_ms += ms(clock) - direct_ms;
            t.direct_ms = direct_ms;
            shown
        } else {
            let mut rgb = self.relight(&px, &code);
            t.network_ms += ms(clock);
            let clock = Instant::now();
            self.complete(ts, camera, &placed, &g, sampling, &mut rgb)?;
            t.direct_ms = ms(clock);
            FrameRadiance::Host(rgb)
        };
        cache.light = Some((key, code));
        cache.still = Some((camera.clone(), g, px));
        Ok((shown, t))
    }

    /// A camera's pixels with the G-buffer left on the device, where the stages can and the
    /// frame needs nothing on the host (traced light to denoise: OIDN runs on the host); the
    /// G-buffer's and the networks' times into `t`.
    fn kept_pixels(
        &self,
        ts: &TraceScene,
        camera: &Camera,
        sampling: &DirectSampling,
        t: &mut FrameTimings,
    ) -> Result<Option<Pixels>> {
        if self.traces_direct() && sampling.denoiser.is_some() {
            return Ok(None);
        }
        let bounds = &self.file.bounds;
        let kept = (self.stages).kept_pixels(&*self.shading, ts, camera, bounds)?;
        let Some(KeptPixels {
            rows,
            gbuffer_ms,
            network_ms,
        }) = kept
        else {
            return Ok(None);
        };
        (t.gbuffer_ms, t.network_ms) = (gbuffer_ms, network_ms);
        let count = (camera.width * camera.height) as usize;
        Ok(Some(Pixels {
            count,
            foreground: (0..count).collect(),
            rows,
            kept: true,
        }))
    }

    /// The G-buffer of `camera`'s pixel centres: rasterised on the GPU beside the kernels (the
    /// scene uploaded at its first frame), traced otherwise.
    pub fn gbuffer(&self, ts: &TraceScene, camera: &Camera) -> Result<GBuffer> {
        self.stages.gbuffer(ts, camera)
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
        self.stages.path_trace(ts, camera, map, settings)
    }

    /// The GPU time of each kernel of a lighting change of the pixels `cache` keeps, under the
    /// lighting it keeps (`nprt bench frame --profile`). None off the GPU kernels or before a
    /// frame.
    #[cfg(feature = "gpu")]
    pub fn profile_relight<K>(
        &self,
        cache: &FrameCache<K>,
    ) -> Result<Option<Vec<nprt_gpu::KernelTime>>> {
        let (Some((_, _, px)), Some((_, light))) = (&cache.still, &cache.light) else {
            return Ok(None);
        };
        if self.shading.host_waits().is_none() {
            return Ok(None);
        }
        (self.stages)
            .profile(&*self.shading, &px.rows, light)
            .map(Some)
    }

    /// Encodes `map` rotated by `rotation_deg` about +Y: on the GPU kernels, queued there and
    /// left on the device.
    pub fn light_code(&self, map: &EnvMap, rotation_deg: f32) -> LightCode {
        self.shading.light_code(map, rotation_deg)
    }

    /// How many times the host has waited for the GPU kernels' queue so far (None off them):
    /// `nprt bench frame` counts a lighting change's.
    pub fn host_waits(&self) -> Option<u64> {
        self.shading.host_waits()
    }

    /// Waits for the work the GPU kernels queued (a light code: [`Self::light_code`] does not
    /// wait), so that a stage timed after is not charged with it; nothing to wait for
    /// elsewhere.
    pub fn settle(&self) -> Result<()> {
        self.shading.settle()
    }

    /// Radiance of every pixel of `g` under `light`; background pixels are zero (see
    /// [`background`]).
    pub fn shade(&self, g: &GBuffer, light: &LightCode) -> Vec<Vec3> {
        self.relight(&self.pixels(g), light)
    }

    /// The network inputs of `g`'s foreground pixels run through what of the networks does
    /// not depend on the lighting, so that [`Self::relight`] under each further lighting runs
    /// only the shading networks.
    pub fn pixels(&self, g: &GBuffer) -> Pixels {
        let foreground: Vec<usize> = (0..g.mask.len()).filter(|&i| g.mask[i] > 0.5).collect();
        let mut features = vec![0.0; foreground.len() * FEATURES];
        features
            .par_chunks_mut(FEATURES)
            .zip(&foreground)
            .for_each(|(f, &i)| f.copy_from_slice(&gbuffer_features(&self.file.bounds, g, i)));
        Pixels {
            count: g.mask.len(),
            foreground,
            rows: self.shading.pixels(&features),
            kept: false,
        }
    }

    /// Floating-point operations of the dense layers per foreground pixel, for a frame from a
    /// new viewpoint or (`transfer_known`) a lighting change under a still camera; None off the
    /// CPU engine.
    pub fn flops_per_pixel(&self, transfer_known: bool) -> Option<f64> {
        self.shading.flops_per_pixel(transfer_known)
    }

    /// Radiance of every pixel under `light`; background pixels are zero.
    pub fn relight(&self, px: &Pixels, light: &LightCode) -> Vec<Vec3> {
        assert!(!px.kept, "pixels kept on the device are finished there");
        let rgb = self.shading.radiance(&px.rows, light);
        let mut out = vec![Vec3::ZERO; px.count];
        for (k, &i) in px.foreground.iter().enumerate() {
            out[i] = Vec3::from_slice(&rgb[3 * k..3 * k + 3]);
        }
        out
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
