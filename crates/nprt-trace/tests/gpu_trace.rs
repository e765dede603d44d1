//! The path tracer on the device (`gpu::RasterGBuffer::trace`, `path_trace.wgsl`)
//! against nprt-trace's on the CPU, which it must estimate without bias: traced direct light
//! (paths of two vertices through the pixel centres, as `render_direct`) and full paths with
//! Russian roulette (as `render`), on a scene with every scattering and material feature and
//! on the built-in room, under a sun. The two use different random numbers, so they agree
//! within noise: over blocks of pixels, the GPU's frame is no further from one CPU frame than
//! a second CPU frame of another seed is. The scene's BVH is built by the first path traced.
//! Gated as the other Vulkan tests are.
#![cfg(feature = "gpu")]

mod common;

use common::features_scene::{features_scene, views};
use common::frame_noise::block_rms;
use glam::Vec3;
use nprt_gpu::GpuDevice;
use nprt_scene::{load_scene, open_envmap, Camera, EnvMap, Scene, SceneOptions};
use nprt_trace::gpu::{GpuPaths, RasterGBuffer};
use nprt_trace::{render, render_direct, PixelFilter, RenderSettings, TraceScene};

/// Every view of `scene` traced with `paths` on the device and by `cpu` with two seeds: the
/// device's frame is within 1.5 times the two CPU frames' difference of the first (and
/// finite everywhere), and its mean within 2% of the CPU's.
fn assert_unbiased(
    scene: &Scene,
    map: &EnvMap,
    size: [u32; 2],
    paths: GpuPaths,
    cpu: impl Fn(&TraceScene, &Camera, u64) -> Vec<Vec3>,
) {
    let ts = TraceScene::new(scene);
    let raster = RasterGBuffer::new(&ts).unwrap();
    // The BVH is made by the first path, not with the scene's upload.
    assert!(!raster.has_bvh());
    for (k, camera) in views(scene, size[0], size[1]).iter().enumerate() {
        let gpu = raster.trace(camera, map, &paths).unwrap();
        assert!(raster.has_bvh());
        let (cpu1, cpu2) = (cpu(&ts, camera, 1), cpu(&ts, camera, 2));
        assert!(gpu.iter().all(|c| c.is_finite() && c.min_element() >= 0.0));
        let (noise, error) = (
            block_rms(&cpu1, &cpu2, camera.width as usize),
            block_rms(&cpu1, &gpu, camera.width as usize),
        );
        let mean = |f: &[Vec3]| f.iter().map(|c| (c.x + c.y + c.z) as f64).sum::<f64>();
        let level = mean(&gpu) / mean(&cpu1);
        eprintln!(
            "{} view {k}, max depth {}: block rms CPU vs CPU {noise:.4}, GPU vs CPU {error:.4}; \
             GPU mean / CPU mean {level:.4}",
            scene.name, paths.max_depth
        );
        assert!(error <= 1.5 * noise, "{} view {k}", scene.name);
        assert!((level - 1.0).abs() < 0.02, "{} view {k}", scene.name);
    }
}

fn sun() -> EnvMap {
    open_envmap("builtin:sky:35:60").unwrap().rotated_y(40.0)
}

fn direct(scene: &Scene, size: [u32; 2], spp: u32) {
    let map = sun();
    let paths = GpuPaths {
        seed: 7,
        ..GpuPaths::direct(spp, 0)
    };
    assert_unbiased(scene, &map, size, paths, |ts, camera, seed| {
        render_direct(ts, camera, &map, spp, seed)
    });
}

/// Full paths through the pixel centres, or (`jitter`) uniformly over each pixel as the
/// viewer's reference and `render`'s box filter take them.
fn full_paths(scene: &Scene, size: [u32; 2], spp: u32, jitter: bool) {
    let map = sun();
    let max_depth = scene.max_depth.unwrap_or(8).min(8);
    let paths = GpuPaths {
        spp,
        seed: 7,
        max_depth,
        rr_depth: scene.rr_depth,
        first_path: 0,
        jitter,
        stratified: false,
    };
    assert_unbiased(scene, &map, size, paths, |ts, camera, seed| {
        let settings = RenderSettings {
            spp,
            max_depth: Some(max_depth),
            rr_depth: scene.rr_depth,
            seed,
            filter: if jitter {
                PixelFilter::Box
            } else {
                PixelFilter::Centre
            },
            progress: false,
        };
        render(ts, camera, &map, &settings).radiance
    });
}

#[test]
fn traced_direct_light_matches_the_cpus_for_every_material_feature() {
    if !GpuDevice::probe() {
        return;
    }
    direct(&features_scene(), [64, 48], 512);
}

#[test]
fn traced_direct_light_matches_the_cpus_on_the_builtin_room() {
    if !GpuDevice::probe() {
        return;
    }
    direct(
        &load_scene("builtin:room", &SceneOptions::default()).unwrap(),
        [64, 48],
        256,
    );
}

#[test]
fn full_paths_match_the_cpus_for_every_material_feature() {
    if !GpuDevice::probe() {
        return;
    }
    full_paths(&features_scene(), [48, 36], 256, false);
}

#[test]
fn jittered_full_paths_match_the_cpus_on_the_builtin_room() {
    if !GpuDevice::probe() {
        return;
    }
    full_paths(
        &load_scene("builtin:room", &SceneOptions::default()).unwrap(),
        [48, 36],
        256,
        true,
    );
}
