//! A relighter's frame on the CPU engine: traced direct light added to every pixel, the
//! model's gain per channel, and denoised direct light closer to the converged one.

use glam::Vec3;
use nprt_net::model::folder::save_model;
use nprt_net::{Design, DirectLight, Engine, Init, ModelConfig, ModelFile};
use nprt_render::oidn::Oidn;
use nprt_render::{background, DirectSampling, Relighter};
use nprt_scene::Camera;
use nprt_trace::{render_direct, render_gbuffer, TraceScene};

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
        let mut rgb = r.shade(&g, (&map, 0.0)).unwrap().0;
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
    let shade = |r: &Relighter| r.shade(&g, (&map, 30.0)).unwrap().0;
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
    let network = traced.shade(&g, (&map, 0.0)).unwrap().0;
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
