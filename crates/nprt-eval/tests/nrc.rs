//! The Neural Radiance Cache baseline against an analytic answer: a diffuse sphere (convex, so
//! it sees only the sky) of albedo a under a constant sky L leaves a · L everywhere. A cold
//! cache read at the first vertex (NRC-CACHE) converges to it frame by frame (NRC too, whose
//! paths here escape before reading the cache); and a change of the sky shows as a spike in
//! the per-frame error of a warmed cache, which lags it, along the temporal evaluation's path.

use glam::Vec3;
use nprt_eval::nrc::{Nrc, NrcSettings};
use nprt_eval::temporal::{run_temporal, TemporalSetup};
use nprt_net::{Compute, Engine};
use nprt_scene::{Camera, CameraVolume, EnvMap, Material, Mesh, Scene};
use nprt_trace::{
    render_gbuffer, CacheRead, PathSettings, PixelFilter, RenderSettings, TraceScene,
};

const ALBEDO: f32 = 0.5;

fn sphere() -> Scene {
    let mut s = Scene::empty("sphere");
    s.add(
        Mesh::sphere(Vec3::ZERO, 1.0, 48),
        Material::diffuse("grey", Vec3::splat(ALBEDO)),
    );
    s
}

const BOUNDS: [[f32; 3]; 2] = [[-1.0; 3], [1.0; 3]];

/// The mean relative error of the foreground pixels of `frame` against `want`.
fn error(frame: &[Vec3], mask: &[f32], want: f32) -> f32 {
    let fg: Vec<Vec3> = (0..mask.len())
        .filter(|&i| mask[i] > 0.5)
        .map(|i| frame[i])
        .collect();
    let mean: Vec3 = fg.iter().sum::<Vec3>() / fg.len() as f32;
    ((mean - Vec3::splat(want)).abs() / want).max_element()
}

/// A cold cache reading as `read` says, trained on `engine` for 41 frames of the furnace
/// sphere: its relative error at the first frame and at the 41st.
fn converge(read: CacheRead, engine: Engine) -> (f32, f32) {
    let scene = sphere();
    let ts = TraceScene::new(&scene);
    let sky = EnvMap::constant(Vec3::ONE).unwrap();
    let camera = Camera::look_at(Vec3::new(0.0, 0.5, 3.0), Vec3::ZERO, Vec3::Y, 50.0, 32, 32);
    let mask = render_gbuffer(&ts, &camera).mask;
    let path = PathSettings {
        max_depth: u32::MAX,
        rr_depth: 5,
    };
    let mut nrc = Nrc::new(NrcSettings::new(read), &BOUNDS, 1, engine).unwrap();
    let mut frame = || error(&nrc.frame(&ts, &camera, &sky, &path), &mask, ALBEDO);
    let first = frame();
    let last = (0..40).map(|_| frame()).last().expect("frames");
    (first, last)
}

#[test]
fn a_cold_cache_converges_to_the_furnace_answer() {
    for read in [CacheRead::FirstVertex, CacheRead::Spread] {
        let (first, last) = converge(read, Engine::Cpu);
        eprintln!("{read:?}: relative error {first:.3} at the first frame, {last:.4} at the 41st");
        assert!(last < 0.03, "{read:?}: {first} → {last}");
    }
}

/// The same cache on the GPU kernels (`--device wgpu`; lavapipe in CI), where this build has
/// them and an adapter.
#[test]
fn the_cache_converges_on_the_gpu_kernels_too() {
    let engine = match Compute::Wgpu.engine() {
        Ok(e) => e,
        Err(e) => {
            let e = format!("{e:#}");
            let wanted = std::env::var_os("NPRT_REQUIRE_VULKAN").is_some();
            assert!(!wanted || e.contains("without its GPU kernels"), "{e}");
            eprintln!("skipped: {e}");
            return;
        }
    };
    let (_, last) = converge(CacheRead::FirstVertex, engine);
    eprintln!("GPU kernels: relative error {last:.4} at the 41st frame");
    assert!(last < 0.03, "{last}");
}

#[test]
fn a_change_of_sky_spikes_a_warmed_caches_error() {
    let scene = sphere();
    let ts = TraceScene::new(&scene);
    let skies = [Vec3::ONE, Vec3::splat(3.0)].map(|l| EnvMap::constant(l).unwrap());
    let volume = CameraVolume {
        min: Vec3::new(-0.2, 0.3, 2.8),
        max: Vec3::new(0.2, 0.7, 3.2),
        look: Vec3::new(0.0, -0.15, -1.0).normalize(),
        spread_deg: 5.0,
        fov_deg: 50.0,
    };
    let tracer = |spp, seed| RenderSettings {
        spp,
        max_depth: None,
        rr_depth: 5,
        seed,
        filter: PixelFilter::Centre,
        progress: false,
    };
    let setup = TemporalSetup {
        ts: &ts,
        volume: &volume,
        maps: [&skies[0], &skies[1]],
        frames: 12,
        resolution: [24, 24],
        reference_spp: 16,
        tracer: &tracer,
        seed: 3,
        direct_spp: 4,
        bounds: BOUNDS,
        nrc_warmup: 30,
        engine: Engine::Cpu,
    };
    let t = run_temporal(&setup, &[], ("pt", 4), None, &|| {}).unwrap();
    let c = t.change_at;
    let l1 = |name: &str| t.method(name).unwrap().per_frame_l1();
    // Converged under the first sky, far off at the change (it still holds a · L), settled
    // again within a few frames (seen: 0.04 before, 1.02 at the change, 0.10 three frames on,
    // its noise at the brighter sky).
    let cache = l1("nrc-cache (warmed 30 frames)");
    eprintln!("NRC-CACHE per-frame L1 {cache:?}");
    assert!(cache[c] > 8.0 * cache[c - 1], "{cache:?}");
    assert!(cache[c + 3] < 0.2 * cache[c], "{cache:?}");
    // Paths that leave a convex sphere never come back to read the cache: NRC is path
    // tracing here, and path tracing has no memory: no spike beyond its noise, which triples
    // with the sky.
    for name in ["nrc (warmed 30 frames)", "pt"] {
        let e = l1(name);
        eprintln!("{name} per-frame L1 {e:?}");
        assert!(e[c] < 4.0 * e[c - 1], "{name}: {e:?}");
    }
}
