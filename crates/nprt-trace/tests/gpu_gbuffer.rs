//! The rasterised G-buffer (`gpu::RasterGBuffer`) against the tracer's pixel-centre
//! G-buffer (`nprt_trace::render_gbuffer`), which it must reproduce: every material feature
//! the G-buffer records (bitmaps through uv transforms, checkerboards, metallic-roughness,
//! Fresnel at normal incidence, opacity masks, bump maps seen from either side, one- and
//! two-sided surfaces, meshes without normals or uvs), the built-in room and, where the shared
//! data is present, the KITCHEN. Gated as the other Vulkan tests are.
#![cfg(feature = "gpu")]

mod common;

use common::features_scene::{features_scene, views};
use glam::Vec3;
use nprt_gpu::GpuDevice;
use nprt_scene::{load_scene, Scene, SceneOptions};
use nprt_trace::gpu::RasterGBuffer;
use nprt_trace::{render_gbuffer, GBuffer, TraceScene};

/// Per pixel, the largest difference of any value of two G-buffers' samples, relative to one
/// plus the value, in increasing order.
fn differences(gpu: &GBuffer, cpu: &GBuffer) -> Vec<f32> {
    assert_eq!(gpu.mask.len(), cpu.mask.len());
    let mut d: Vec<f32> = (0..cpu.mask.len())
        .map(|i| {
            let (a, b) = (gpu.sample(i), cpu.sample(i));
            [
                (a.position, b.position),
                (a.normal, b.normal),
                (a.view, b.view),
                (a.kd, b.kd),
                (a.ks, b.ks),
                (Vec3::splat(a.alpha), Vec3::splat(b.alpha)),
                (Vec3::splat(a.mask), Vec3::splat(b.mask)),
            ]
            .iter()
            .map(|(x, y)| (*x - *y).abs().max_element() / (1.0 + y.abs().max_element()))
            .fold(0.0f32, f32::max)
        })
        .collect();
    d.sort_by(f32::total_cmp);
    d
}

/// Every view of `scene` rasterised (each into the buffer the last one handed back) and traced.
/// Where the two see the same point they agree
/// to f32 rounding; they part where a pixel centre falls on an edge, so that each takes a
/// neighbour (a silhouette, a uv seam), or where rounding moves a lookup across a texel
/// boundary, at which a bump map's bilinear gradient jumps. So: at most `share` of the pixels
/// differ beyond 10⁻³, at most 1% beyond 10⁻⁵, and the median pixel agrees within 10⁻⁶
/// (relative to one plus the value).
fn assert_matches(scene: &Scene, width: u32, height: u32, share: f64) {
    let ts = TraceScene::new(scene);
    let raster = RasterGBuffer::new(&ts).unwrap();
    for (k, camera) in views(scene, width, height).iter().enumerate() {
        let gpu = raster.render(camera).unwrap();
        let cpu = render_gbuffer(&ts, camera);
        let foreground = cpu.mask.iter().filter(|&&m| m > 0.5).count();
        let d = differences(&gpu, &cpu);
        let beyond = |bound: f32| d.iter().filter(|&&x| x > bound).count() as f64 / d.len() as f64;
        let (median, coarse, fine) = (d[d.len() / 2], beyond(1e-3), beyond(1e-5));
        eprintln!(
            "{} view {k} ({width}x{height}, {foreground} foreground): median difference {median:.1e}; \
             {:.2}% of pixels beyond 1e-5, {:.2}% beyond 1e-3",
            scene.name,
            100.0 * fine,
            100.0 * coarse
        );
        assert!(foreground > d.len() / 4, "the view sees the scene");
        assert!(
            coarse <= share && fine <= 0.01 && median <= 1e-6,
            "{} view {k}",
            scene.name
        );
    }
}

#[test]
fn rasterised_gbuffer_matches_the_tracers_for_every_material_feature() {
    if !GpuDevice::probe() {
        return;
    }
    let scene = features_scene();
    assert_matches(&scene, 160, 120, 0.003);
    // The same raster at another size (its targets are remade).
    assert_matches(&scene, 37, 23, 0.01);
}

#[test]
fn rasterised_gbuffer_matches_the_tracers_on_the_builtin_room() {
    if !GpuDevice::probe() {
        return;
    }
    let scene = load_scene("builtin:room", &SceneOptions::default()).unwrap();
    assert_matches(&scene, 128, 96, 0.003);
}

/// The KITCHEN at scale: a million triangles, its textures, bump maps and the blinds' mask.
#[test]
fn rasterised_gbuffer_matches_the_tracers_on_the_kitchen() {
    let Some(kitchen) = common::shared("scenes/kitchen/scene.xml") else {
        return;
    };
    if !GpuDevice::probe() {
        return;
    }
    let scene = load_scene(kitchen.to_str().unwrap(), &SceneOptions::default()).unwrap();
    assert_matches(&scene, 160, 120, 0.01);
}
