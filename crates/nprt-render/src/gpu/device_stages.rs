//! A frame's stages on the GPU, beside nprt-net's networks on the GPU kernels (a
//! [`DeviceShading`]): the scene rasterised into a G-buffer that stays on the device, the
//! networks' inputs made there, the background recorded into the networks' own compute pass,
//! and traced light on the tracer's kernels, all on the process's one device.

use std::sync::Arc;
use std::time::Instant;

use anyhow::Result;
use glam::Vec3;
use nprt_gpu::{GpuDevice, KeptLast, KernelTime, PooledBuffer};
use nprt_net::gpu::{DeviceShading, GpuLightCode, GpuPixels};
use nprt_scene::{Camera, EnvMap};
use nprt_trace::gpu::{record_paths, GpuPaths, PathTargets, RasterGBuffer};
use nprt_trace::{GBuffer, PixelFilter, RenderSettings, TraceScene};

use super::frame_background::{record_background, Background, Fill};
use crate::frame_stages::{DirectRays, FrameRadiance, FrameStages, KeptPixels, KeptStages, Rows};

/// The stages on the GPU: the scene of the last frame on the device (by its address: a model
/// renders the one scene it was trained on).
#[derive(Default)]
pub struct DeviceStages {
    raster: KeptLast<usize, Arc<RasterGBuffer>>,
}

/// Pixels of a G-buffer that stayed on the device: a row per pixel, its samples and camera.
pub struct KeptGBuffer {
    px: GpuPixels,
    samples: PooledBuffer,
    camera: Camera,
}

impl DeviceStages {
    /// The scene on the device, uploaded unless it was the last frame's.
    fn raster(&self, ts: &TraceScene) -> Result<Arc<RasterGBuffer>> {
        let key = std::ptr::from_ref(&*ts.scene) as usize;
        self.raster
            .try_get(key, || RasterGBuffer::new(ts).map(Arc::new))
    }
}

impl FrameStages for DeviceStages {
    fn gbuffer(&self, ts: &TraceScene, camera: &Camera) -> Result<GBuffer> {
        self.raster(ts)?.render(camera)
    }

    fn traced_direct(
        &self,
        ts: &TraceScene,
        camera: &Camera,
        map: &EnvMap,
        (spp, seed): DirectRays,
    ) -> Result<Vec<Vec3>> {
        self.raster(ts)?
            .trace(camera, map, &GpuPaths::direct(spp, seed))
    }

    fn path_trace(
        &self,
        ts: &TraceScene,
        camera: &Camera,
        map: &EnvMap,
        settings: &RenderSettings,
    ) -> Result<Vec<Vec3>> {
        let paths = GpuPaths {
            spp: settings.spp,
            seed: settings.seed,
            max_depth: settings.max_depth.unwrap_or(u32::MAX),
            rr_depth: settings.rr_depth,
            first_path: 0,
            jitter: matches!(settings.filter, PixelFilter::Box),
            stratified: false,
        };
        self.raster(ts)?.trace(camera, map, &paths)
    }

    fn gbuffer_on(&self) -> &'static str {
        "rasterised on the GPU"
    }

    fn paths_on(&self) -> &'static str {
        "on the GPU"
    }
}

impl<N: DeviceShading> KeptStages<N> for DeviceStages {
    type Kept = KeptGBuffer;

    /// Rasterised, then every pixel's inputs and the light-independent networks, the queue
    /// waited for after each so that the stages can be told apart.
    fn kept_pixels(
        &self,
        net: &N,
        ts: &TraceScene,
        camera: &Camera,
        bounds: &[[f32; 3]; 2],
    ) -> Result<Option<KeptPixels<KeptGBuffer>>> {
        let device = GpuDevice::get()?;
        let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
        let raster = self.raster(ts)?;
        let clock = Instant::now();
        let samples = raster.samples(camera)?;
        device.wait();
        let gbuffer_ms = ms(clock);
        let clock = Instant::now();
        let count = (camera.width * camera.height) as usize;
        let px = net.pixels_of_gbuffer(&samples, count, bounds);
        device.wait();
        let rows = KeptGBuffer {
            px,
            samples,
            camera: camera.clone(),
        };
        Ok(Some(KeptPixels {
            rows,
            gbuffer_ms,
            network_ms: ms(clock),
        }))
    }

    /// The networks and the background in one submission; traced light, where asked, in one
    /// after it (timed alone); read back once, or left on the device.
    fn kept_frame(
        &self,
        net: &N,
        ts: &TraceScene,
        kept: &KeptGBuffer,
        code: &GpuLightCode,
        map: &EnvMap,
        direct: Option<DirectRays>,
        keep: bool,
    ) -> Result<(FrameRadiance, f64)> {
        let gpu = GpuDevice::get()?;
        let background = Background {
            samples: &kept.samples,
            camera: &kept.camera,
            fill: match direct {
                Some(_) => Fill::TracedDirect(map),
                None => Fill::Map(map),
            },
        };
        net.queue_radiance(&kept.px, code, &mut |pass, rgb| {
            record_background(net.maps(), &gpu, pass, &background, rgb);
        });
        let mut direct_ms = 0.0;
        if let Some((spp, seed)) = direct {
            let raster = self.raster(ts)?;
            gpu.wait();
            let clock = Instant::now();
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let out = PathTargets {
                rgb: kept.px.rgb(),
                direct: None,
                add: true,
            };
            record_paths(
                &gpu,
                &mut encoder.begin_compute_pass(&Default::default()),
                raster.scene(),
                net.maps(),
                &kept.camera,
                map,
                &GpuPaths::direct(spp, seed),
                &out,
            );
            gpu.queue.submit([encoder.finish()]);
            gpu.wait();
            direct_ms = clock.elapsed().as_secs_f64() * 1e3;
        }
        let pixels = kept.px.rows;
        if keep {
            gpu.wait();
            let rgb = kept.px.rgb().clone();
            return Ok((FrameRadiance::Device { rgb, pixels }, direct_ms));
        }
        let rgb = gpu.read(kept.px.rgb(), 3 * pixels);
        let rgb = rgb.chunks_exact(3).map(Vec3::from_slice).collect();
        Ok((FrameRadiance::Host(rgb), direct_ms))
    }

    fn profile(
        &self,
        net: &N,
        rows: Rows<&GpuPixels, &KeptGBuffer>,
        code: &GpuLightCode,
    ) -> Result<Vec<KernelTime>> {
        let px = match rows {
            Rows::Networks(px) => px,
            Rows::Kept(kept) => &kept.px,
        };
        net.profile_relight(px, code)
    }
}
