//! Frames that stay on the GPU from the G-buffer to the finished frame (nprt-render's
//! `Relighter::frame` on the kernels, for models whose networks give all the light): the
//! rasterised G-buffer, the encoder's input from the map, every pixel's inputs and networks,
//! and the background from the map,
//! against the CPU's frame (the tracer's G-buffer, the CPU engine, the map on the host) of the
//! same model, camera and lighting, for a new viewpoint and for a lighting change under it; and
//! for a model that leaves direct light to the tracer, that light traced on the device, within
//! noise of the CPU tracer's. Runs on Mesa's software Vulkan in CI (gated as the other Vulkan
//! tests).
#![cfg(feature = "gpu")]

mod common;

use common::trimmed_block_rms;
use glam::Vec3;
use nprt_net::model::folder::ModelFile;
use nprt_net::{Compute, Design, DirectLight, Engine, Init, ModelConfig};
use nprt_render::{DirectSampling, FrameCache, Relighter};
use nprt_scene::{Camera, Material, Mesh, Scene};
use nprt_trace::TraceScene;

/// A glossy sphere on a floor, seen with sky around them: foreground and background pixels.
fn scene() -> Scene {
    let mut scene = Scene::empty("sphere on a floor");
    scene.add(
        Mesh::sphere(Vec3::new(0.0, 1.0, 0.0), 1.0, 32),
        Material::glossy("ball", Vec3::new(0.6, 0.3, 0.2), Vec3::splat(0.2), 0.1),
    );
    let mut floor = Mesh::rectangle();
    floor.transform(
        glam::Mat4::from_scale(Vec3::splat(2.5))
            * glam::Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2),
    );
    scene.add(floor, Material::diffuse("floor", Vec3::splat(0.5)));
    scene
}

/// A 64 × 48 view of [`scene`] with sky above the sphere.
fn camera() -> Camera {
    Camera::look_at(
        Vec3::new(0.5, 2.5, 5.0),
        Vec3::new(0.0, 0.8, 0.0),
        Vec3::Y,
        60.0,
        64,
        48,
    )
}

/// An untrained model of `config` for `scene` on the CPU engine and on the GPU kernels.
fn relighters(config: ModelConfig, scene: &Scene) -> (Relighter, Relighter) {
    let wgpu = Compute::Wgpu.engine().unwrap();
    let (lo, hi) = scene.bounds();
    let net = config.build(&mut Init::new(5));
    let file = ModelFile::untrained(config, &net, [lo.to_array(), hi.to_array()]);
    let cpu = Relighter::new(file.clone(), net.clone(), Engine::Cpu).unwrap();
    let gpu = Relighter::new(file, net, wgpu).unwrap();
    (cpu, gpu)
}

/// How far `gpu` is from `cpu`: the share of pixels beyond 1e-5 of the brightest value, and the
/// median pixel's difference over it.
fn compare(gpu: &[Vec3], cpu: &[Vec3]) -> (f64, f32) {
    let peak = cpu.iter().fold(0.0f32, |m, c| m.max(c.max_element()));
    let mut off: Vec<f32> = gpu
        .iter()
        .zip(cpu)
        .map(|(a, b)| (*a - *b).abs().max_element() / peak)
        .collect();
    off.sort_by(f32::total_cmp);
    let beyond = off.iter().filter(|&&d| d > 1e-5).count() as f64 / off.len() as f64;
    (beyond, off[off.len() / 2])
}

#[test]
fn frames_on_the_gpu_match_the_cpus_with_their_background() {
    if !common::wgpu_runs() {
        return;
    }
    let scene = scene();
    let ts = TraceScene::new(&scene);
    let camera = camera();
    let map = nprt_scene::open_envmap("builtin:sky").unwrap();
    let sampling = DirectSampling {
        spp: 1,
        seed: 0,
        denoiser: None,
    };
    for design in [Design::Dsep, Design::Baseline] {
        let config = ModelConfig {
            encoder_width: 64,
            ..ModelConfig::new(design, None)
        };
        let (cpu, gpu) = relighters(config, &scene);
        assert_eq!(gpu.gbuffer_on(), "rasterised on the GPU");
        let (mut on_cpu, mut on_gpu) = (FrameCache::default(), FrameCache::default());
        // A new viewpoint, then a lighting change under it (the transfer networks' outputs
        // kept on the device).
        for (key, rotation) in [(0, 30.0), (1, 100.0)] {
            let (want, _) = cpu
                .frame(&mut on_cpu, &ts, &camera, &map, rotation, key, sampling)
                .unwrap();
            let (got, t) = gpu
                .frame(&mut on_gpu, &ts, &camera, &map, rotation, key, sampling)
                .unwrap();
            let background = on_cpu.foreground() < want.len();
            assert!(background, "the view shows the sky");
            assert_eq!(on_gpu.foreground(), want.len(), "every pixel has a row");
            let (beyond, median) = compare(&got, &want);
            eprintln!(
                "{design:?} at rotation {rotation}: {:.2}% of pixels beyond 1e-5, median {median:.1e} (G-buffer {:.1} ms, networks {:.1} ms)",
                100.0 * beyond,
                t.gbuffer_ms,
                t.network_ms
            );
            // The median carries the encoder's input, made on the device from lookups whose
            // trigonometry rounds its own way: within 5e-6 of the host's near a sun's edge,
            // light codes within 1.0e-6 (nprt-net's tests/gpu_frame.rs); lavapipe: at most 1.0e-6.
            assert!(beyond <= 0.01 && median < 3e-6, "{design:?}");
        }
    }
}

/// Models that trace their direct light, D/S and the recommended recipe's (the linear design
/// on sh:2): on the device the frame is the networks' plus direct light traced there, in one
/// submission; it agrees with the CPU's frame (the CPU tracer's light) within the noise two
/// CPU frames of different seeds show. The recipe's denoised on the host.
#[test]
fn traced_direct_light_stays_on_the_gpu_and_matches_the_cpus_within_noise() {
    if !common::wgpu_runs() {
        return;
    }
    let dsep = ModelConfig {
        encoder_width: 64,
        direct: DirectLight::Traced,
        ..ModelConfig::new(Design::Dsep, None)
    };
    for config in [dsep, nprt_net::RECIPE.config()] {
        traced_frames_agree(config);
    }
}

fn traced_frames_agree(config: ModelConfig) {
    let scene = scene();
    let ts = TraceScene::new(&scene);
    let camera = camera();
    let map = nprt_scene::open_envmap("builtin:sky:30:50").unwrap();
    let label = config.label();
    let recipe = config == nprt_net::RECIPE.config();
    let (cpu, gpu) = relighters(config, &scene);
    let frame = |r: &Relighter, seed| {
        let sampling = DirectSampling {
            spp: 256,
            seed,
            denoiser: None,
        };
        r.frame(
            &mut FrameCache::default(),
            &ts,
            &camera,
            &map,
            30.0,
            0,
            sampling,
        )
        .unwrap()
    };
    let ((cpu1, _), (cpu2, _), (got, t)) = (frame(&cpu, 1), frame(&cpu, 2), frame(&gpu, 3));
    // Trimmed of the 2% of blocks that differ most: with each pixel's samples stratified the
    // noise is mostly the sun's rare paths off the glossy ball, and the plain rms of 192 blocks
    // swung from 0.0074 to 0.0143 between pairs of frames that agree at 2,048 spp.
    let width = camera.width as usize;
    let (noise, error) = (
        trimmed_block_rms(&cpu1, &cpu2, width),
        trimmed_block_rms(&cpu1, &got, width),
    );
    eprintln!(
        "{label}: block rms CPU vs CPU {noise:.4}, GPU vs CPU {error:.4} (G-buffer {:.1} ms, networks {:.1} ms, direct light {:.1} ms)",
        t.gbuffer_ms, t.network_ms, t.direct_ms
    );
    assert!(t.direct_ms > 0.0, "the traced light timed apart");
    assert!(error <= 1.5 * noise && noise < 0.05, "{label}");
    if !recipe {
        return;
    }

    // Denoised, the light traced on the device goes through OIDN on the host: a few paths per
    // pixel come out closer to the converged frame than without it.
    let oidn = match nprt_render::oidn::Oidn::open() {
        Ok(o) => o,
        Err(e) if std::env::var_os("NPRT_REQUIRE_OIDN").is_none() => {
            eprintln!("skipped the denoised frame: {e:#}");
            return;
        }
        Err(e) => panic!("NPRT_REQUIRE_OIDN is set but {e:#}"),
    };
    let few = |denoiser| {
        let sampling = DirectSampling {
            spp: 2,
            seed: 4,
            denoiser,
        };
        gpu.frame(
            &mut FrameCache::default(),
            &ts,
            &camera,
            &map,
            30.0,
            0,
            sampling,
        )
        .unwrap()
    };
    let converged = {
        let sampling = DirectSampling {
            spp: 1024,
            seed: 5,
            denoiser: None,
        };
        cpu.frame(
            &mut FrameCache::default(),
            &ts,
            &camera,
            &map,
            30.0,
            0,
            sampling,
        )
        .unwrap()
        .0
    };
    let l1 = |f: &[Vec3]| {
        f.iter()
            .zip(&converged)
            .map(|(a, b)| (*a - *b).abs().element_sum())
            .sum::<f32>()
    };
    let ((raw, _), (denoised, t)) = (few(None), few(Some(oidn)));
    eprintln!(
        "L1 to the converged frame: raw {:.1}, denoised {:.1} (direct light {:.1} ms)",
        l1(&raw),
        l1(&denoised),
        t.direct_ms
    );
    assert!(l1(&denoised) < 0.5 * l1(&raw));
}

/// `nprt render --precision f16` (f16 weights and activations, f32 sums: tensor cores where the
/// adapter has them, a plain kernel on Mesa's software Vulkan) of a trained D/S model with the
/// hash grid against its f32 frames: the same image within 1% of the mean in L1. f16 refused
/// where the networks run on the CPU.
#[test]
fn half_precision_frames_of_a_trained_model_follow_f32() {
    if !common::wgpu_runs() {
        return;
    }
    let dir = common::fresh_dir("half-frames");
    let model = common::tiny_room_model(&dir, &["--arch", "dsep", "--encoding", "hash-grid"]);
    let m = model.to_str().unwrap();
    let frames = |precision: &str| {
        let out = dir.join(precision);
        common::ok(&[
            "render",
            "--model",
            m,
            "--out",
            out.to_str().unwrap(),
            "--frames",
            "2",
            "--res",
            "64x48",
            "--exr",
            "--device",
            "wgpu",
            "--precision",
            precision,
        ]);
        (0..2)
            .flat_map(|i| {
                let path = out.join(format!("frames/{i:04}.exr"));
                let (_, _, ch) = nprt_io::exr::read_channels(&path).unwrap();
                let [r, g, b] = ["R", "G", "B"].map(|c| ch[c].clone());
                (0..r.len())
                    .flat_map(move |p| [r[p], g[p], b[p]])
                    .collect::<Vec<_>>()
            })
            .collect::<Vec<f32>>()
    };
    let (full, half) = (frames("f32"), frames("f16"));
    let diff: f32 = full.iter().zip(&half).map(|(a, b)| (a - b).abs()).sum();
    let error = diff / full.iter().map(|v| v.abs()).sum::<f32>();
    eprintln!("f16 frames: mean |f16 − f32| {error:.2e} of the mean");
    assert!(error < 1e-2, "f16 frames off by {error} of the mean");
    common::fails(
        &[
            "render",
            "--model",
            m,
            "--out",
            dir.join("cpu").to_str().unwrap(),
            "--frames",
            "1",
            "--device",
            "cpu",
            "--precision",
            "f16",
        ],
        &["--precision f16", "--device wgpu"],
    );
}
