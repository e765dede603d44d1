//! Baselines against analytic answers: SH PRT of a diffuse plane under a constant sky (the
//! furnace answer kd·L), SH PRT against path tracing under a smooth map, and OIDN on noise.

use glam::{Vec2, Vec3};
use nprt_eval::metrics::Metrics;
use nprt_eval::sh::ShTransport;
use nprt_net::encoding::spherical_harmonics::basis;
use nprt_scene::envmap::uv_to_direction;
use nprt_scene::{Camera, EnvMap, Material, Mesh, Scene};
use nprt_trace::{render, PixelFilter, RenderSettings, TraceScene};

/// A 10×10 plane at y = 0 facing up, looked at from above.
fn plane(kd: f32) -> (Scene, Camera) {
    let mut s = Scene::empty("plane");
    let mesh = Mesh {
        name: "plane".into(),
        positions: vec![
            Vec3::new(-5.0, 0.0, -5.0),
            Vec3::new(5.0, 0.0, -5.0),
            Vec3::new(5.0, 0.0, 5.0),
            Vec3::new(-5.0, 0.0, 5.0),
        ],
        normals: vec![],
        uvs: vec![],
        indices: vec![[0, 2, 1], [0, 3, 2]],
        material: 0,
    };
    s.add(mesh, Material::diffuse("grey", Vec3::splat(kd)));
    let cam = Camera::look_at(Vec3::new(0.0, 3.0, 0.5), Vec3::ZERO, Vec3::Y, 40.0, 8, 8);
    (s, cam)
}

fn settings(spp: u32) -> RenderSettings {
    RenderSettings {
        spp,
        max_depth: None,
        rr_depth: 5,
        seed: 7,
        filter: PixelFilter::Centre,
        progress: false,
    }
}

#[test]
fn sh_prt_of_a_diffuse_plane_under_a_constant_sky_is_kd_times_l() {
    let (scene, cam) = plane(0.6);
    let ts = TraceScene::new(&scene);
    let t = ShTransport::precompute(&ts, &cam, 5, &settings(512));
    for bands in [3, 5] {
        let rgb = t
            .truncated(bands)
            .shade(&EnvMap::constant(Vec3::new(1.0, 2.0, 0.5)).unwrap());
        for px in &rgb {
            // Cosine-weighted sampling of a diffuse plane gives throughput kd exactly: no noise.
            assert!(
                (*px - Vec3::new(0.6, 1.2, 0.3)).abs().max_element() < 1e-3,
                "{bands} bands: {px}"
            );
        }
    }
}

#[test]
fn sh_prt_25_approaches_path_tracing_under_a_smooth_sky() {
    // A sky of bands ≤ 2 is reproduced exactly by 9 and 25 coefficients; only noise remains.
    let (w, h) = (128, 64);
    let texels = (0..w * h)
        .map(|i| {
            let d = uv_to_direction(Vec2::new(
                ((i % w) as f32 + 0.5) / w as f32,
                ((i / w) as f32 + 0.5) / h as f32,
            ));
            Vec3::new(1.0 + 0.8 * d.y, 1.0 + 0.5 * d.x, 1.0 + 0.6 * d.y * d.y)
        })
        .collect();
    let map = EnvMap::from_texels("smooth", w, h, texels).unwrap();
    let (scene, cam) = plane(0.5);
    let ts = TraceScene::new(&scene);
    let pt = render(&ts, &cam, &map, &settings(4096));
    let mask = vec![1.0; 64];
    let t = ShTransport::precompute(&ts, &cam, 5, &settings(4096));
    for bands in [3, 5] {
        let m = Metrics::compute(&t.truncated(bands).shade(&map), &pt.radiance, &mask, 8);
        assert!(m.mape < 0.01, "{bands} bands: {m:?}");
    }
    // The basis is the one the projection uses.
    let mut y = [0.0; 9];
    basis(3, Vec3::Y, &mut y);
    assert!((y[1] - 0.488_602_5).abs() < 1e-6);
}

#[test]
fn oidn_denoises_when_installed() {
    let oidn = match nprt_render::oidn::Oidn::open() {
        Ok(o) => o,
        Err(e) if std::env::var_os("NPRT_REQUIRE_OIDN").is_none() => {
            eprintln!("skipping: {e:#}");
            return;
        }
        Err(e) => panic!("NPRT_REQUIRE_OIDN is set but {e:#}"),
    };
    let (w, h) = (64, 64);
    let clean = vec![Vec3::splat(0.5); w * h];
    let mut state = 12345u32;
    let noisy: Vec<Vec3> = clean
        .iter()
        .map(|c| {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            *c * (0.5 + (state >> 8) as f32 / (1 << 24) as f32)
        })
        .collect();
    let albedo = vec![Vec3::splat(0.8); w * h];
    let normal = vec![Vec3::Y; w * h];
    let out = oidn.denoise(&noisy, &albedo, &normal, w, h).unwrap();
    let mask = vec![1.0; w * h];
    let before = Metrics::compute(&noisy, &clean, &mask, w).l1;
    let after = Metrics::compute(&out, &clean, &mask, w).l1;
    assert!(after < before * 0.3, "OIDN: L1 {before} → {after}");
}
