//! Cases with known answers: furnaces, a diffuse plane under a constant sky, Mitsuba's
//! max_depth semantics, direct light alone, and determinism.

use glam::{Mat4, Vec3};
use nprt_scene::{Camera, EnvMap, Material, Mesh, Scene};
use nprt_trace::{render, render_direct, Frame, PixelFilter, RenderSettings, TraceScene};

fn settings(spp: u32, max_depth: Option<u32>) -> RenderSettings {
    RenderSettings {
        spp,
        max_depth,
        rr_depth: 5,
        seed: 7,
        filter: PixelFilter::Box,
        progress: false,
    }
}

fn sphere_scene(material: Material) -> Scene {
    let mut s = Scene::empty("sphere");
    s.add(Mesh::sphere(Vec3::ZERO, 1.0, 64), material);
    s
}

/// Mean radiance over pixels whose centre sees geometry.
fn foreground_mean(f: &Frame) -> Vec3 {
    let (mut sum, mut n) = (Vec3::ZERO, 0.0);
    for (r, m) in f.radiance.iter().zip(&f.gbuffer.mask) {
        if *m > 0.0 {
            sum += *r;
            n += 1.0;
        }
    }
    sum / n
}

fn camera() -> Camera {
    Camera::look_at(Vec3::new(0.0, 0.0, 2.2), Vec3::ZERO, Vec3::Y, 40.0, 32, 32)
}

#[test]
fn white_furnace_returns_the_environment() {
    // A white diffuse object under a unit sky: every path ends in the sky carrying 1.
    let mut white = Material::diffuse("white", Vec3::ONE);
    white.two_sided = false;
    let s = sphere_scene(white);
    let ts = TraceScene::new(&s);
    let f = render(
        &ts,
        &camera(),
        &EnvMap::constant(Vec3::ONE).unwrap(),
        &settings(64, None),
    );
    let m = foreground_mean(&f);
    assert!(
        (m - Vec3::ONE).abs().max_element() < 0.005,
        "furnace mean {m}"
    );
    // No pixel deviates beyond noise either (64 spp with Russian roulette: σ ≈ 0.03).
    let worst = f
        .radiance
        .iter()
        .map(|r| (r.x - 1.0).abs())
        .fold(0.0, f32::max);
    assert!(worst < 0.15, "a pixel strays from 1 by {worst}");
}

#[test]
fn convex_diffuse_object_reflects_albedo_times_sky() {
    // A convex object sees only the sky: L = kd · L_sky, in every channel, direct light only.
    let kd = Vec3::new(0.2, 0.5, 0.8);
    let s = sphere_scene(Material::diffuse("d", kd));
    let ts = TraceScene::new(&s);
    let sky = Vec3::new(2.0, 1.0, 0.5);
    let f = render(
        &ts,
        &camera(),
        &EnvMap::constant(sky).unwrap(),
        &settings(64, None),
    );
    let m = foreground_mean(&f);
    let expected = kd * sky;
    assert!(
        ((m - expected) / expected).abs().max_element() < 0.01,
        "{m} vs {expected}"
    );
    let direct: Vec3 = f.direct.iter().sum::<Vec3>() / f.direct.len() as f32;
    let total = f.mean();
    assert!(
        ((direct - total) / total).abs().max_element() < 1e-3,
        "a convex object has no indirect light"
    );
}

#[test]
fn diffuse_plane_under_constant_map() {
    // An upward-facing plane under a uniform sky: irradiance π·L, radiance kd·L, with
    // direct illumination alone (max_depth 2) and with full transport alike.
    let mut s = Scene::empty("plane");
    let mut plane = Mesh::rectangle();
    plane.transform(
        Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2) * Mat4::from_scale(Vec3::splat(50.0)),
    );
    s.add(plane, Material::diffuse("d", Vec3::splat(0.6)));
    let ts = TraceScene::new(&s);
    let cam = Camera::look_at(
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::Y,
        45.0,
        24,
        24,
    );
    for depth in [Some(2), None] {
        let f = render(
            &ts,
            &cam,
            &EnvMap::constant(Vec3::splat(1.5)).unwrap(),
            &settings(64, depth),
        );
        let m = foreground_mean(&f);
        assert!((m.x - 0.9).abs() < 0.01, "max_depth {depth:?}: {m}");
    }
}

#[test]
fn max_depth_follows_mitsuba() {
    let s = sphere_scene(Material::diffuse("d", Vec3::splat(0.5)));
    let ts = TraceScene::new(&s);
    let env = EnvMap::constant(Vec3::ONE).unwrap();
    // max_depth 1: only the emitter seen directly; surfaces are black. Through pixel centres
    // every pixel is exactly the sky (1) or a surface (0).
    let centre = RenderSettings {
        filter: PixelFilter::Centre,
        ..settings(4, Some(1))
    };
    let f = render(&ts, &camera(), &env, &centre);
    for (r, m) in f.radiance.iter().zip(&f.gbuffer.mask) {
        assert_eq!(r.x, 1.0 - *m, "pixel with mask {m} has radiance {r}");
    }
    assert!(f.gbuffer.mask.iter().sum::<f32>() > 100.0);
    // max_depth 2 lights the sphere (direct only), so surfaces are no longer black.
    let f = render(
        &ts,
        &camera(),
        &env,
        &RenderSettings {
            max_depth: Some(2),
            ..centre
        },
    );
    assert!(
        (foreground_mean(&f).x - 0.5).abs() < 0.02,
        "{}",
        foreground_mean(&f)
    );
    // max_depth 0: nothing at all.
    assert_eq!(
        render(&ts, &camera(), &env, &settings(1, Some(0))).mean(),
        Vec3::ZERO
    );
}

#[test]
fn direct_light_alone_is_the_depth_two_render_less_noisy_and_the_full_render_s_direct_part() {
    let s = nprt_scene::builtin::scene("room").unwrap();
    let ts = TraceScene::new(&s);
    let cam = s.camera.clone().unwrap().with_resolution(24, 24);
    let env = s.envmap.clone().unwrap();
    let centre = |spp, max_depth| RenderSettings {
        filter: PixelFilter::Centre,
        ..settings(spp, max_depth)
    };
    // The reference tracer stopped after the first bounce, in the mean, with less noise: its
    // samples stratified (nprt_trace::sampler), the tracer's independent.
    let converged = render(&ts, &cam, &env, &centre(2048, Some(2))).radiance;
    let rms = |v: &[Vec3]| {
        let sq: f32 = (v.iter().zip(&converged))
            .map(|(a, b)| (*a - *b).length_squared())
            .sum();
        (sq / v.len() as f32).sqrt()
    };
    let (stratified, independent) = (
        rms(&render_direct(&ts, &cam, &env, 16, 7)),
        rms(&render(&ts, &cam, &env, &centre(16, Some(2))).radiance),
    );
    assert!(
        stratified < 0.9 * independent,
        "rms error at 16 spp: stratified {stratified}, independent {independent}"
    );
    // And, in the mean, the direct part the full render splits off, well short of its total
    // (the room has indirect light), so it cannot be the total by mistake.
    let full = render(&ts, &cam, &env, &centre(256, None));
    let direct = render_direct(&ts, &cam, &env, 256, 9);
    let mean = |v: &[Vec3]| v.iter().sum::<Vec3>() / v.len() as f32;
    let (d, split, total) = (mean(&direct), mean(&full.direct), mean(&full.radiance));
    assert!(
        ((d - split) / split).abs().max_element() < 0.03,
        "direct alone {d} against the full render's direct part {split}"
    );
    assert!(
        (total - d).min_element() > 0.1 * total.min_element(),
        "direct {d} against total {total}"
    );
}

#[test]
fn same_seed_same_image_whatever_the_thread_count() {
    let s = nprt_scene::builtin::scene("room").unwrap();
    let ts = TraceScene::new(&s);
    let cam = s.camera.clone().unwrap().with_resolution(24, 24);
    let env = s.envmap.clone().unwrap();
    let run = |threads: usize, seed: u64| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let st = RenderSettings {
            seed,
            ..settings(4, Some(5))
        };
        pool.install(|| render(&ts, &cam, &env, &st))
    };
    let (a, b, c) = (run(1, 3), run(2, 3), run(2, 4));
    assert_eq!(a.radiance, b.radiance);
    assert_eq!(a.gbuffer.position, b.gbuffer.position);
    assert_ne!(a.radiance, c.radiance);
}

#[test]
fn gbuffer_holds_the_centre_hit() {
    let s = sphere_scene(Material::glossy(
        "g",
        Vec3::splat(0.25),
        Vec3::splat(0.5),
        0.3,
    ));
    let ts = TraceScene::new(&s);
    let cam = Camera::look_at(Vec3::new(0.0, 0.0, 2.2), Vec3::ZERO, Vec3::Y, 70.0, 32, 32);
    let f = render(
        &ts,
        &cam,
        &EnvMap::constant(Vec3::ONE).unwrap(),
        &RenderSettings {
            filter: PixelFilter::Centre,
            ..settings(1, Some(3))
        },
    );
    let c = 16 * 32 + 16;
    let g = &f.gbuffer;
    assert_eq!(g.mask[c], 1.0);
    assert!((g.position[c].length() - 1.0).abs() < 1e-3);
    assert!(
        g.normal[c].dot(g.view[c]) > 0.99,
        "normal faces the camera at the centre"
    );
    assert_eq!(
        (g.kd[c], g.ks[c], g.alpha[c]),
        (Vec3::splat(0.25), Vec3::splat(0.5), 0.3)
    );
    assert_eq!(g.mask[0], 0.0);
    // The frame survives an EXR round trip channel for channel.
    let path = std::env::temp_dir().join(format!("nprt-gb-{}.exr", std::process::id()));
    f.write_exr(&path).unwrap();
    let (w, h, ch) = nprt_io::exr::read_channels(&path).unwrap();
    assert_eq!((w, h), (32, 32));
    for (name, data) in f.channels() {
        assert_eq!(ch[&name], data, "channel {name}");
    }
}
