//! nprt-trace's path tracer on the device (`shaders/path_trace.wgsl`): the scene's BVH walked
//! in a compute shader, so it runs on every adapter. A frame's traced direct light (paths of
//! two vertices) and the viewer's progressive reference (full paths) are the same kernel.

use anyhow::Result;
use glam::Vec3;
use nprt_gpu::{GpuDevice, KernelSource};
use nprt_scene::{Camera, EnvMap};

use crate::{Frame, PixelFilter, RenderSettings};

use super::gpu_map::{map_frame_words, matrix_words, GpuMap};
use super::gpu_scene::GpuScene;
use super::raster_gbuffer::{camera_words, RasterGBuffer};

pub const PATH_TRACE: KernelSource = KernelSource {
    name: "path_trace",
    wgsl: concat!(
        include_str!("shaders/camera_ray.wgsl"),
        include_str!("shaders/lerp.wgsl"),
        include_str!("shaders/map_lookup.wgsl"),
        include_str!("shaders/map_sampling.wgsl"),
        include_str!("shaders/surface.wgsl"),
        include_str!("shaders/bsdf.wgsl"),
        include_str!("shaders/bvh.wgsl"),
        include_str!("shaders/path_trace.wgsl")
    ),
};

/// Paths per pixel in one dispatch: a long dispatch is cut short on Mesa's software Vulkan
/// (one of 1,024 paths per pixel gave two thirds of the light; passes of 16 give it all) and
/// risks a desktop driver's watchdog, so an estimate is split into dispatches of this many.
const PATHS_PER_DISPATCH: u32 = 16;

/// Which paths a pass traces: nprt-trace's `RenderSettings` for the device.
#[derive(Clone, Copy, Debug)]
pub struct GpuPaths {
    /// Paths per pixel in this pass.
    pub spp: u32,
    pub seed: u64,
    /// Path vertices, as Mitsuba counts them (2: direct light).
    pub max_depth: u32,
    pub rr_depth: u32,
    /// The index of the pass's first path per pixel: a progressive render's passes draw fresh
    /// paths by counting on.
    pub first_path: u32,
    /// Over the pixel (a reference's box filter) rather than through its centre (the
    /// G-buffer's, and traced direct light's, convention).
    pub jitter: bool,
    /// The first dimensions of a pixel's `spp` paths stratified, as the CPU's traced direct
    /// light (nprt-trace's `StratifiedSampler`); independent numbers otherwise.
    pub stratified: bool,
}

impl GpuPaths {
    /// Traced direct light's paths, as nprt-trace's `render_direct` traces them: `spp` paths
    /// of two vertices through each pixel centre.
    pub fn direct(spp: u32, seed: u64) -> Self {
        GpuPaths {
            spp,
            seed,
            max_depth: 2,
            rr_depth: u32::MAX,
            first_path: 0,
            jitter: false,
            stratified: true,
        }
    }
}

/// Where a pass's mean goes: the radiance into `rgb` (3 f32 per pixel) and, where given, its
/// direct part into `direct` (as the CPU tracer's `PathRadiance::direct`), written, or with `add`
/// added to what they hold.
pub struct PathTargets<'a> {
    pub rgb: &'a wgpu::Buffer,
    pub direct: Option<&'a wgpu::Buffer>,
    pub add: bool,
}

/// Records a pass of `paths` through `camera` under `map` (as placed in the world) into
/// `out`.
#[allow(clippy::too_many_arguments)]
pub fn record_paths(
    gpu: &GpuDevice,
    pass: &mut wgpu::ComputePass,
    scene: &GpuScene,
    maps: &GpuMap,
    camera: &Camera,
    map: &EnvMap,
    paths: &GpuPaths,
    out: &PathTargets,
) {
    let texels = maps.texels(gpu, map);
    let table = maps.table(gpu, map);
    let bvh = scene.bvh(gpu);
    let (seed, triangles) = (
        (paths.seed ^ (paths.seed >> 32)) as u32,
        scene.triangle_count,
    );
    for first in (0..paths.spp).step_by(PATHS_PER_DISPATCH as usize) {
        let mut params = vec![
            camera.width,
            camera.height,
            PATHS_PER_DISPATCH.min(paths.spp - first),
            paths.spp,
            seed,
            paths.max_depth,
            paths.rr_depth,
            paths.first_path + first,
            u32::from(out.add || first > 0),
            u32::from(paths.jitter),
            triangles,
            u32::from(out.direct.is_some()),
            u32::from(paths.stratified),
            0,
            0,
            0,
        ];
        params.extend(camera_words(camera));
        params.extend(map_frame_words(map));
        params.extend(matrix_words(map.to_world()));
        gpu.dispatch(
            pass,
            &PATH_TRACE,
            &params,
            &[
                &scene.positions,
                &scene.attributes,
                &scene.triangles,
                &scene.materials,
                &scene.textures,
                &scene.bitmaps,
                &bvh.nodes,
                &bvh.triangles,
                &texels,
                &table,
                out.rgb,
                out.direct.unwrap_or(&gpu.spare),
            ],
            [camera.width.div_ceil(8), camera.height.div_ceil(8)],
        );
    }
}

impl RasterGBuffer {
    /// The mean radiance of `paths` per pixel of `camera` under `map` (as placed in the world),
    /// traced on the device and read back.
    pub fn trace(&self, camera: &Camera, map: &EnvMap, paths: &GpuPaths) -> Result<Vec<Vec3>> {
        Ok(self.traced(camera, map, paths, false)?.0)
    }

    /// [`Self::trace`], and the direct part of the same paths (the map seen directly, and light
    /// that reached the first surface straight from it).
    pub fn trace_with_direct(
        &self,
        camera: &Camera,
        map: &EnvMap,
        paths: &GpuPaths,
    ) -> Result<(Vec<Vec3>, Vec<Vec3>)> {
        let (radiance, direct) = self.traced(camera, map, paths, true)?;
        Ok((radiance, direct.expect("the direct part was asked for")))
    }

    /// A frame as [`crate::render`] makes it with `settings`, on the device: the G-buffer
    /// (rasterised), radiance and its direct part (traced).
    pub fn render_frame(
        &self,
        camera: &Camera,
        map: &EnvMap,
        settings: &RenderSettings,
    ) -> Result<Frame> {
        let paths = GpuPaths {
            spp: settings.spp,
            seed: settings.seed,
            max_depth: settings.max_depth.unwrap_or(u32::MAX),
            rr_depth: settings.rr_depth,
            first_path: 0,
            jitter: settings.filter == PixelFilter::Box,
            stratified: false,
        };
        let gbuffer = self.render(camera)?;
        let (radiance, direct) = self.trace_with_direct(camera, map, &paths)?;
        Ok(Frame {
            width: camera.width as usize,
            height: camera.height as usize,
            radiance,
            direct,
            gbuffer,
        })
    }

    fn traced(
        &self,
        camera: &Camera,
        map: &EnvMap,
        paths: &GpuPaths,
        with_direct: bool,
    ) -> Result<(Vec<Vec3>, Option<Vec<Vec3>>)> {
        let gpu = self.device();
        let pixels = (camera.width * camera.height) as usize;
        gpu.check_binding(
            12 * pixels,
            &format!("a {}×{} traced frame", camera.width, camera.height),
        )?;
        let rgb = self.pooled(3 * pixels);
        let direct = with_direct.then(|| self.pooled(3 * pixels));
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            let out = PathTargets {
                rgb: &rgb,
                direct: direct.as_deref(),
                add: false,
            };
            let (scene, maps) = (self.scene(), self.maps());
            record_paths(gpu, &mut pass, scene, maps, camera, map, paths, &out);
        }
        gpu.queue.submit([encoder.finish()]);
        let read = |buffer: &wgpu::Buffer| -> Vec<Vec3> {
            gpu.read(buffer, 3 * pixels)
                .chunks_exact(3)
                .map(Vec3::from_slice)
                .collect()
        };
        Ok((read(&rgb), direct.as_deref().map(read)))
    }
}
