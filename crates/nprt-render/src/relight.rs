//! The run-time network: light code once per lighting change, transport on foreground pixels,
//! for a still camera the light-independent part (the transfer networks' ŝ) kept between
//! lighting changes, and for models that leave direct light to the tracer, that light traced.

use std::path::Path;
use std::time::Instant;

use anyhow::Result;
use glam::{Vec2, Vec3};
use nprt_net::cpu::TransferCodes;
use nprt_net::gbuffer_features;
use nprt_net::{load_model, DirectLight, Engine, LightInput, ModelFile, NprtNet, FEATURES};
use nprt_scene::{Camera, EnvMap};
use nprt_trace::{render, render_direct, render_gbuffer, GBuffer, RenderSettings, TraceScene};
#[cfg(feature = "wgpu")]
use {nprt_gpu::KeptLast, nprt_trace::gpu::RasterGBuffer, std::sync::Arc};

use crate::frame_timings::FrameTimings;
use crate::Precision;

use crate::oidn::Oidn;
use rayon::prelude::*;

/// Samples per pixel of the traced direct light when none is asked for: on the demo, D/S with
/// traced direct light beats equal-time path tracing in every metric from 4 spp, by a margin
/// that grows with the count; 16 takes most of it (docs/model.md#traced-direct-light).
pub const DEFAULT_DIRECT_SPP: u32 = 16;

/// A trained model ready to shade G-buffers.
pub struct Relighter {
    pub file: ModelFile,
    /// The weights; the CPU engine runs them where frames are made on the CPU.
    net: NprtNet,
    /// The encoder and transport networks as our own kernels, where frames are made there.
    #[cfg(feature = "wgpu")]
    gpu: Option<crate::gpu::GpuNetwork>,
    /// With the kernels, the scene of the last frame on the device (by its address: a model
    /// renders the one scene it was trained on) for its rasterised G-buffers.
    #[cfg(feature = "wgpu")]
    raster: KeptLast<usize, Arc<RasterGBuffer>>,
}

/// What the encoder made of one lighting: the 64-d code ê and what the map's channels were
/// divided by (the model's gain multiplies the radiance besides). On the frame path's kernels
/// both stay on the device, where the encoder left them.
#[derive(Clone)]
pub struct LightCode(Code);

#[derive(Clone)]
enum Code {
    Host {
        code: Vec<f32>,
        divisor: [f32; 3],
    },
    #[cfg(feature = "wgpu")]
    Device(crate::gpu::GpuLightCode),
}

/// A frame's radiance, 3 f32 a pixel in pixel order: on the host, or left on the device by
/// the GPU kernels ([`Relighter::frame_shown`]).
pub enum FrameRadiance {
    Host(Vec<Vec3>),
    #[cfg(feature = "wgpu")]
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
            #[cfg(feature = "wgpu")]
            FrameRadiance::Device { rgb, pixels } => {
                let gpu = nprt_gpu::GpuDevice::get().expect("a frame on the device has one");
                let rgb = gpu.read(&rgb, 3 * pixels);
                rgb.chunks_exact(3).map(Vec3::from_slice).collect()
            }
        }
    }
}

/// A G-buffer's foreground pixels as network inputs, and what of the network does not depend
/// on the lighting: all a still camera needs to relight.
pub struct Pixels {
    count: usize,
    foreground: Vec<usize>,
    features: Vec<f32>,
    transfer: Option<TransferCodes>,
    #[cfg(feature = "wgpu")]
    gpu: Option<crate::gpu::GpuPixels>,
    /// A G-buffer that stayed on the device (every pixel then has a row) and its camera.
    #[cfg(feature = "wgpu")]
    gbuffer: Option<(nprt_gpu::PooledBuffer, Camera)>,
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
    /// Loads the model in `dir` to run on `engine`: the CPU engine, or the frame path's own
    /// kernels (crate::gpu), which upload the weights read on the host.
    pub fn load(dir: &Path, engine: Engine) -> Result<Self> {
        let (file, net) = load_model(dir)?;
        Self::new(file, net, engine)
    }

    /// A model with `file`'s settings and the weights of `net` (on the host), to run on
    /// `engine`.
    pub fn new(file: ModelFile, net: NprtNet, engine: Engine) -> Result<Self> {
        #[cfg(feature = "wgpu")]
        if engine.is_gpu() {
            let gpu = Some(crate::gpu::GpuNetwork::new(&net, file.output_gain())?);
            return Ok(Relighter {
                file,
                net,
                gpu,
                raster: Default::default(),
            });
        }
        anyhow::ensure!(
            !engine.is_gpu(),
            "this nprt-render was built without its GPU kernels (feature `wgpu`)"
        );
        Ok(Relighter {
            file,
            net,
            #[cfg(feature = "wgpu")]
            gpu: None,
            #[cfg(feature = "wgpu")]
            raster: Default::default(),
        })
    }

    /// Runs the networks in `precision`; f16 needs the GPU kernels (`--device gpu`) and an
    /// adapter with f16 in shaders. Frames made after use it, with a new [`FrameCache`].
    pub fn set_precision(&mut self, precision: Precision) -> Result<()> {
        #[cfg(feature = "wgpu")]
        if let Some(gpu) = &mut self.gpu {
            return gpu.set_half(precision == Precision::F16);
        }
        if precision == Precision::F16 {
            anyhow::bail!(
                "--precision f16 runs on the GPU kernels only (--device gpu or --device wgpu)"
            );
        }
        Ok(())
    }

    /// The precision the networks run in.
    pub fn precision(&self) -> Precision {
        #[cfg(feature = "wgpu")]
        if self.gpu.as_ref().is_some_and(|g| g.half()) {
            return Precision::F16;
        }
        Precision::F32
    }

    /// Where the networks run, for reports: "CPU engine" or "GPU kernels on ADAPTER".
    pub fn networks_on(&self) -> String {
        #[cfg(feature = "wgpu")]
        if let Some(gpu) = &self.gpu {
            return match gpu.half() {
                false => format!("GPU kernels on {}", gpu.adapter()),
                true => format!("GPU kernels on {} ({})", gpu.adapter(), gpu.precision()),
            };
        }
        "CPU engine".into()
    }

    /// Where the G-buffer is made, for reports: rasterised beside the GPU kernels, or the CPU
    /// tracer's primary rays.
    pub fn gbuffer_on(&self) -> &'static str {
        if self.kernels_on_gpu() {
            "rasterised on the GPU"
        } else {
            "traced on the CPU"
        }
    }

    /// Where [`Self::path_trace`] and traced direct light run, for reports.
    pub fn paths_on(&self) -> &'static str {
        if self.kernels_on_gpu() {
            "on the GPU"
        } else {
            "on the CPU"
        }
    }

    fn kernels_on_gpu(&self) -> bool {
        #[cfg(feature = "wgpu")]
        if self.gpu.is_some() {
            return true;
        }
        false
    }

    /// Whether the model leaves direct light to the tracer ([`Self::complete`] traces it).
    pub fn traces_direct(&self) -> bool {
        self.file.config.direct == DirectLight::Traced
    }

    /// Completes a frame the network shaded (`rgb`, background pixels zero) from G-buffer `g`
    /// under `map` (the lighting as placed in the world): for a model that traces direct light,
    /// adds every pixel's direct light, traced through the pixel centre as `sampling` says (on
    /// background pixels that is the map itself; on the device with the kernels, the CPU
    /// tracer otherwise); otherwise fills background pixels with the map.
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
        let mut direct = self.traced_direct(ts, camera, map, sampling)?;
        if let Some(oidn) = sampling.denoiser {
            let (w, h) = (camera.width as usize, camera.height as usize);
            direct = oidn.denoise_frame(&direct, g, w, h)?;
        }
        rgb.par_iter_mut().zip(direct).for_each(|(c, d)| *c += d);
        Ok(())
    }

    /// Every pixel's direct light through its centre, as `sampling` says (its denoiser aside).
    fn traced_direct(
        &self,
        ts: &TraceScene,
        camera: &Camera,
        map: &EnvMap,
        sampling: DirectSampling,
    ) -> Result<Vec<Vec3>> {
        #[cfg(feature = "wgpu")]
        if self.gpu.is_some() {
            let paths = nprt_trace::gpu::GpuPaths::direct(sampling.spp, sampling.seed);
            return self.raster(ts)?.trace(camera, map, &paths);
        }
        Ok(render_direct(ts, camera, map, sampling.spp, sampling.seed))
    }

    /// One frame through `camera` under `map` turned by `rotation_deg` (the lighting `key`
    /// names): the G-buffer and the light-independent networks only when the camera moved
    /// since the frame `cache` holds, the encoder only when the key changed, then the shading
    /// networks and [`Self::complete`] (on the kernels, for a model whose networks give all
    /// the light, the whole frame on the device, its background included). Returns the
    /// radiance and each stage's time.
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

    /// [`Self::frame`], its radiance left on the device where the GPU kernels made the whole
    /// frame there and `keep` asks (what `nprt view` shows), read back otherwise.
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
            #[cfg(feature = "wgpu")]
            _ if self.frames_on_device(&sampling) => {
                let (px, gbuffer_ms, network_ms) = self.device_pixels(ts, camera)?;
                (t.gbuffer_ms, t.network_ms) = (gbuffer_ms, network_ms);
                (GBuffer::default(), px)
            }
            _ => {
                let clock = Instant::now();
                let g = self.gbuffer(ts, camera)?;
                t.gbuffer_ms = ms(clock);
                let clock = Instant::now();
                let px = self.pixels(&g);
                t.network_ms = ms(clock);
                (g, px)
            }
        };
        let placed = map.rotated_y(rotation_deg);
        let clock = Instant::now();
        let finished = self.device_frame(ts, &px, &code, &placed, &sampling, keep)?;
        let shown = match finished {
            Some((shown, direct_ms)) => {
                t.network_ms += ms(clock) - direct_ms;
                t.direct_ms = direct_ms;
                shown
            }
            None => {
                let mut rgb = self.relight(&px, &code);
                t.network_ms += ms(clock);
                let clock = Instant::now();
                self.complete(ts, camera, &placed, &g, sampling, &mut rgb)?;
                t.direct_ms = ms(clock);
                FrameRadiance::Host(rgb)
            }
        };
        cache.light = Some((key, code));
        cache.still = Some((camera.clone(), g, px));
        Ok((shown, t))
    }

    /// The G-buffer of `camera`'s pixel centres: rasterised on the GPU with the kernels (the
    /// scene uploaded at its first frame), traced otherwise.
    pub fn gbuffer(&self, ts: &TraceScene, camera: &Camera) -> Result<GBuffer> {
        #[cfg(feature = "wgpu")]
        if self.gpu.is_some() {
            return self.raster(ts)?.render(camera);
        }
        Ok(render_gbuffer(ts, camera))
    }

    /// One pass of path tracing of `camera`'s view under `map` (as placed in the world), as
    /// `settings` says: on the device where this model's frames are made there (the scene's
    /// upload shared with the rasterised G-buffer), on the CPU otherwise.
    pub fn path_trace(
        &self,
        ts: &TraceScene,
        camera: &Camera,
        map: &EnvMap,
        settings: &RenderSettings,
    ) -> Result<Vec<Vec3>> {
        #[cfg(feature = "wgpu")]
        if self.gpu.is_some() {
            let paths = nprt_trace::gpu::GpuPaths {
                spp: settings.spp,
                seed: settings.seed,
                max_depth: settings.max_depth.unwrap_or(u32::MAX),
                rr_depth: settings.rr_depth,
                first_path: 0,
                jitter: matches!(settings.filter, nprt_trace::PixelFilter::Box),
            };
            return self.raster(ts)?.trace(camera, map, &paths);
        }
        Ok(render(ts, camera, map, settings).radiance)
    }

    /// The scene on the device, uploaded unless it was the last frame's.
    #[cfg(feature = "wgpu")]
    fn raster(&self, ts: &TraceScene) -> Result<Arc<RasterGBuffer>> {
        let key = std::ptr::from_ref(&*ts.scene) as usize;
        self.raster
            .try_get(key, || RasterGBuffer::new(ts).map(Arc::new))
    }

    /// Whether frames stay on the device from the G-buffer to the finished frame: on the
    /// kernels, with traced direct light traced there too, unless it is to be denoised (OIDN
    /// runs on the host: the G-buffer and the traced light are read back for it).
    #[cfg(feature = "wgpu")]
    fn frames_on_device(&self, sampling: &DirectSampling) -> bool {
        self.gpu.is_some() && !(self.traces_direct() && sampling.denoiser.is_some())
    }

    /// A camera's pixels with the G-buffer left on the device: rasterised, then every pixel's
    /// inputs and the light-independent networks; with the milliseconds of each (the queue
    /// waited for after each, so that the stages can be told apart).
    #[cfg(feature = "wgpu")]
    fn device_pixels(&self, ts: &TraceScene, camera: &Camera) -> Result<(Pixels, f64, f64)> {
        let gpu = self
            .gpu
            .as_ref()
            .expect("frames on the device have the kernels");
        let device = nprt_gpu::GpuDevice::get()?;
        let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
        let raster = self.raster(ts)?;
        let clock = Instant::now();
        let samples = raster.samples(camera)?;
        device.wait();
        let gbuffer_ms = ms(clock);
        let clock = Instant::now();
        let count = (camera.width * camera.height) as usize;
        let pixels = gpu.pixels_of_gbuffer(&samples, count, &self.file.bounds);
        device.wait();
        let px = Pixels {
            count,
            foreground: (0..count).collect(),
            features: Vec::new(),
            transfer: None,
            gpu: Some(pixels),
            gbuffer: Some((samples, camera.clone())),
        };
        Ok((px, gbuffer_ms, ms(clock)))
    }

    /// The finished frame of pixels whose G-buffer stayed on the device, under `light` and
    /// with `map` (as placed in the world) behind, or for a model that traces direct light,
    /// that light traced there as `sampling` says: made there, read back once; with the
    /// milliseconds of the traced light. None for pixels on the host.
    #[cfg_attr(not(feature = "wgpu"), allow(unused_variables))]
    fn device_frame(
        &self,
        ts: &TraceScene,
        px: &Pixels,
        light: &LightCode,
        map: &EnvMap,
        sampling: &DirectSampling,
        keep: bool,
    ) -> Result<Option<(FrameRadiance, f64)>> {
        #[cfg(feature = "wgpu")]
        if let (Some(gpu), Some(pixels), Some((samples, camera))) =
            (&self.gpu, &px.gpu, &px.gbuffer)
        {
            let raster = self.raster(ts)?;
            let background = crate::gpu::Background {
                samples,
                camera,
                fill: if self.traces_direct() {
                    crate::gpu::Fill::TracedDirect {
                        map,
                        scene: &raster,
                        spp: sampling.spp,
                        seed: sampling.seed,
                    }
                } else {
                    crate::gpu::Fill::Map(map)
                },
            };
            let code = self.device_light(light);
            if keep {
                let direct_ms = gpu.radiance_on_device(pixels, &code, Some(&background));
                let shown = FrameRadiance::Device {
                    rgb: pixels.rgb().clone(),
                    pixels: pixels.rows,
                };
                return Ok(Some((shown, direct_ms)));
            }
            let (rgb, direct_ms) = gpu.radiance(pixels, &code, Some(&background));
            let rgb = rgb.chunks_exact(3).map(Vec3::from_slice).collect();
            return Ok(Some((FrameRadiance::Host(rgb), direct_ms)));
        }
        Ok(None)
    }

    /// The GPU time of each kernel of a lighting change of the pixels `cache` keeps, under the
    /// lighting it keeps (`nprt bench frame --profile`): each dispatch timed in a pass of its
    /// own. None where the networks do not run on the GPU kernels or no frame was made yet.
    #[cfg(feature = "wgpu")]
    pub fn profile_relight<K>(
        &self,
        cache: &FrameCache<K>,
    ) -> Result<Option<Vec<nprt_gpu::KernelTime>>> {
        let (Some(gpu), Some((_, _, px)), Some((_, light))) =
            (&self.gpu, &cache.still, &cache.light)
        else {
            return Ok(None);
        };
        let Some(pixels) = &px.gpu else {
            return Ok(None);
        };
        gpu.profile_relight(pixels, &self.device_light(light))
            .map(Some)
    }

    /// Encodes `map` rotated by `rotation_deg` about +Y: on the GPU kernels, queued there and
    /// left on the device.
    pub fn light_code(&self, map: &EnvMap, rotation_deg: f32) -> LightCode {
        let config = &self.file.config;
        #[cfg(feature = "wgpu")]
        if let Some(gpu) = &self.gpu {
            let (width, norm) = (config.encoder_width, config.map_norm);
            return LightCode(Code::Device(gpu.encode_map(map, rotation_deg, width, norm)));
        }
        let input = LightInput::new(map, rotation_deg, config.encoder_width, config.map_norm);
        LightCode(Code::Host {
            code: self.net.encoder.forward(&input.pixels, input.width).codes,
            divisor: input.scale,
        })
    }

    /// `light`'s code on the host, and the scale of each radiance channel: the map's divisor
    /// times the model's gain.
    fn host_light(&self, light: &LightCode) -> (Vec<f32>, [f32; 3]) {
        let (code, divisor) = match &light.0 {
            Code::Host { code, divisor } => (code.clone(), *divisor),
            #[cfg(feature = "wgpu")]
            Code::Device(code) => code.read(
                &nprt_gpu::GpuDevice::get().expect("a light code on the device has a device"),
            ),
        };
        let gain = self.file.output_gain();
        (code, std::array::from_fn(|k| divisor[k] * gain[k]))
    }

    /// `light` on the device, uploaded where it was made on the host.
    #[cfg(feature = "wgpu")]
    fn device_light(&self, light: &LightCode) -> crate::gpu::GpuLightCode {
        match &light.0 {
            Code::Device(code) => code.clone(),
            Code::Host { code, divisor } => crate::gpu::GpuLightCode::upload(
                &nprt_gpu::GpuDevice::get().expect("frames on the device have a device"),
                code,
                *divisor,
            ),
        }
    }

    /// How many times the host has waited for the GPU kernels' queue so far (None off them):
    /// `nprt bench frame` counts a lighting change's.
    pub fn host_waits(&self) -> Option<u64> {
        #[cfg(feature = "wgpu")]
        if self.gpu.is_some() {
            return nprt_gpu::GpuDevice::get().ok().map(|d| d.host_waits());
        }
        None
    }

    /// Waits for the work the GPU kernels queued (a light code: [`Self::light_code`] does not
    /// wait), so that a stage timed after is not charged with it; nothing to wait for
    /// elsewhere.
    pub fn settle(&self) -> Result<()> {
        #[cfg(feature = "wgpu")]
        if self.gpu.is_some() {
            nprt_gpu::GpuDevice::get()?.wait();
        }
        Ok(())
    }

    /// Radiance of every pixel of `g` under `light`; background pixels are zero (see
    /// [`background`]).
    pub fn shade(&self, g: &GBuffer, light: &LightCode) -> Vec<Vec3> {
        self.relight(&self.pixels(g), light)
    }

    /// The network inputs of `g`'s foreground pixels and, on the CPU engine, the transfer
    /// networks' outputs (same work as running them inline), so that [`Self::relight`] under
    /// each further lighting runs only the shading networks.
    pub fn pixels(&self, g: &GBuffer) -> Pixels {
        let foreground: Vec<usize> = (0..g.mask.len()).filter(|&i| g.mask[i] > 0.5).collect();
        let mut features = vec![0.0; foreground.len() * FEATURES];
        features
            .par_chunks_mut(FEATURES)
            .zip(&foreground)
            .for_each(|(f, &i)| f.copy_from_slice(&gbuffer_features(&self.file.bounds, g, i)));
        let transfer = self.host().map(|h| h.transfer_codes(&features));
        Pixels {
            count: g.mask.len(),
            foreground,
            #[cfg(feature = "wgpu")]
            gpu: self.gpu.as_ref().map(|gpu| gpu.pixels(&features)),
            #[cfg(feature = "wgpu")]
            gbuffer: None,
            features,
            transfer,
        }
    }

    /// Floating-point operations of the dense layers per foreground pixel, for a frame from a
    /// new viewpoint or (`transfer_known`) a lighting change under a still camera; None off the
    /// CPU engine.
    pub fn flops_per_pixel(&self, transfer_known: bool) -> Option<f64> {
        self.host().map(|h| h.flops_per_pixel(transfer_known))
    }

    /// The network, where the CPU engine makes the frames.
    fn host(&self) -> Option<&NprtNet> {
        #[cfg(feature = "wgpu")]
        if self.gpu.is_some() {
            return None;
        }
        Some(&self.net)
    }

    /// Radiance of every pixel under `light`; background pixels are zero.
    pub fn relight(&self, px: &Pixels, light: &LightCode) -> Vec<Vec3> {
        let rgb = match self.host() {
            Some(host) => {
                let (code, scale) = self.host_light(light);
                host.radiance(&px.features, &code, scale, px.transfer.as_ref())
            }
            None => self.device_radiance(px, light),
        };
        let mut out = vec![Vec3::ZERO; px.count];
        for (k, &i) in px.foreground.iter().enumerate() {
            out[i] = Vec3::from_slice(&rgb[3 * k..3 * k + 3]);
        }
        out
    }

    /// Radiance (`n × 3`) of the pixels on the frame path's kernels.
    fn device_radiance(&self, px: &Pixels, light: &LightCode) -> Vec<f32> {
        #[cfg(feature = "wgpu")]
        if let (Some(gpu), Some(pixels)) = (&self.gpu, &px.gpu) {
            let code = self.device_light(light);
            // A G-buffer on the device gives every pixel a row: the background's are zeroed.
            let background = px
                .gbuffer
                .as_ref()
                .map(|(samples, camera)| crate::gpu::Background {
                    samples,
                    camera,
                    fill: crate::gpu::Fill::Zero,
                });
            return gpu.radiance(pixels, &code, background.as_ref()).0;
        }
        let _ = (px, light);
        unreachable!("a Relighter without the CPU engine has the GPU kernels")
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

#[cfg(test)]
mod tests {
    use super::*;
    use nprt_net::model::folder::save_model;
    use nprt_net::{Design, Init, ModelConfig};
    use nprt_trace::render_gbuffer;

    /// A unit sphere of `material` at the origin, `segments` around: these tests' scene.
    fn sphere(material: nprt_scene::Material, segments: u32) -> nprt_scene::Scene {
        let mut scene = nprt_scene::Scene::empty("sphere");
        scene.add(
            nprt_scene::Mesh::sphere(Vec3::ZERO, 1.0, segments),
            material,
        );
        scene
    }

    /// A `width` × `height` camera looking at the sphere from above the +Z axis.
    fn camera(width: u32, height: u32) -> Camera {
        Camera::look_at(
            Vec3::new(0.0, 0.5, 2.5),
            Vec3::ZERO,
            Vec3::Y,
            60.0,
            width,
            height,
        )
    }

    /// An untrained D/S model saved to a fresh folder, with its direct light `direct`.
    fn relighter(direct: DirectLight) -> Relighter {
        calibrated(direct, None)
    }

    /// [`relighter`] with its output calibrated by `level_gain`.
    fn calibrated(direct: DirectLight, level_gain: Option<[f32; 3]>) -> Relighter {
        let config = ModelConfig {
            encoder_width: 64,
            direct,
            ..ModelConfig::new(Design::Dsep, None)
        };
        let net = config.build(&mut Init::new(3));
        let file = ModelFile {
            level_gain,
            ..ModelFile::untrained(config, &net, [[-3.0; 3], [3.0; 3]])
        };
        // One folder per call: tests run in parallel.
        static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("nprt-relight-{}-{call}", std::process::id()));
        save_model(&dir, &file, &net).unwrap();
        let r = Relighter::load(&dir, Engine::Cpu).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        r
    }

    #[test]
    fn a_model_that_traces_direct_light_adds_it_to_every_pixel() {
        // A glossy sphere before a sky: foreground and background pixels.
        let scene = sphere(
            nprt_scene::Material::glossy("g", Vec3::splat(0.3), Vec3::splat(0.2), 0.2),
            32,
        );
        let ts = TraceScene::new(&scene);
        let camera = camera(16, 12);
        let map = nprt_scene::open_envmap("builtin:sky").unwrap();
        let g = render_gbuffer(&ts, &camera);
        assert!(g.mask.contains(&0.0) && g.mask.contains(&1.0));
        let sampling = DirectSampling {
            spp: 2,
            seed: 5,
            denoiser: None,
        };
        let frame = |r: &Relighter| {
            let mut rgb = r.shade(&g, &r.light_code(&map, 0.0));
            let network = rgb.clone();
            r.complete(&ts, &camera, &map, &g, sampling, &mut rgb)
                .unwrap();
            (network, rgb)
        };
        let direct = render_direct(&ts, &camera, &map, sampling.spp, sampling.seed);
        let mut sky = vec![Vec3::ZERO; g.mask.len()];
        background(&camera, &map, &g.mask, &mut sky);

        let learned = relighter(DirectLight::Learned);
        assert!(!learned.traces_direct());
        let (network, rgb) = frame(&learned);
        for i in 0..rgb.len() {
            let want = if g.mask[i] > 0.5 { network[i] } else { sky[i] };
            assert_eq!(rgb[i], want, "learned, pixel {i}");
        }

        let traced = relighter(DirectLight::Traced);
        assert!(traced.traces_direct());
        let (network, rgb) = frame(&traced);
        for i in 0..rgb.len() {
            assert_eq!(rgb[i], network[i] + direct[i], "traced, pixel {i}");
            if g.mask[i] <= 0.5 {
                // The map seen directly through the pixel centre, as the learned model's sky.
                assert!((rgb[i] - sky[i]).abs().max_element() <= 1e-6 * sky[i].max_element());
            }
        }
    }

    #[test]
    fn a_calibrated_model_multiplies_each_channel_of_the_network_by_its_gain() {
        let scene = sphere(nprt_scene::Material::diffuse("d", Vec3::splat(0.5)), 32);
        let ts = TraceScene::new(&scene);
        let camera = camera(16, 12);
        let map = nprt_scene::open_envmap("builtin:sky").unwrap();
        let g = render_gbuffer(&ts, &camera);
        let gain = Vec3::new(2.0, 1.0, 0.5);
        let shade = |r: &Relighter| r.shade(&g, &r.light_code(&map, 30.0));
        let plain = shade(&relighter(DirectLight::Traced));
        let scaled = shade(&calibrated(DirectLight::Traced, Some(gain.to_array())));
        let mut lit = 0;
        for (i, (p, s)) in plain.iter().zip(&scaled).enumerate() {
            let want = *p * gain;
            assert!(
                (*s - want).abs().max_element() <= 1e-5 * want.max_element(),
                "pixel {i}: {s} against {want}"
            );
            lit += usize::from(p.min_element() > 0.0);
        }
        assert!(lit > 0, "the untrained network shades something");
    }

    #[test]
    fn denoised_direct_light_is_closer_to_the_converged_one() {
        let oidn = match Oidn::open() {
            Ok(o) => o,
            Err(e) if std::env::var_os("NPRT_REQUIRE_OIDN").is_none() => {
                eprintln!("skipping: {e:#}");
                return;
            }
            Err(e) => panic!("NPRT_REQUIRE_OIDN is set but {e:#}"),
        };
        let scene = sphere(nprt_scene::Material::diffuse("d", Vec3::splat(0.5)), 64);
        let ts = TraceScene::new(&scene);
        let camera = camera(64, 48);
        let map = nprt_scene::open_envmap("builtin:sky").unwrap();
        let g = render_gbuffer(&ts, &camera);
        let traced = relighter(DirectLight::Traced);
        let code = traced.light_code(&map, 0.0);
        let network = traced.shade(&g, &code);
        // The direct light each way: the frame less what the network added.
        let direct = |denoiser| {
            let mut rgb = network.clone();
            let sampling = DirectSampling {
                spp: 2,
                seed: 1,
                denoiser,
            };
            traced
                .complete(&ts, &camera, &map, &g, sampling, &mut rgb)
                .unwrap();
            rgb.iter()
                .zip(&network)
                .map(|(c, n)| *c - *n)
                .collect::<Vec<_>>()
        };
        let converged = render_direct(&ts, &camera, &map, 1024, 2);
        let l1 = |v: &[Vec3]| {
            let fg = (0..v.len()).filter(|&i| g.mask[i] > 0.5);
            fg.map(|i| (v[i] - converged[i]).abs().element_sum())
                .sum::<f32>()
        };
        let (raw, denoised) = (l1(&direct(None)), l1(&direct(Some(oidn))));
        assert!(denoised < 0.5 * raw, "L1 raw {raw}, denoised {denoised}");
    }
}
