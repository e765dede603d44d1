//! `nprt bench frame`: what a relit frame costs, stage by stage (G-buffer, light encoder,
//! networks, direct light), per design and resolution, on the device the networks run on.
//! Untrained networks are timed: a frame's cost does not depend on the weights.

use anyhow::Result;
use nprt_net::model::folder::ModelFile;
use nprt_net::{Design, DirectLight, Engine, Init, ModelConfig};
use nprt_scene::{load_scene, Camera, EnvMap, SceneOptions};
use nprt_trace::TraceScene;

use crate::frame_stages::DirectSampling;
use crate::frame_timings::FrameTimings;
use crate::relight::{FrameCache, Relighter};
use crate::{CameraPath, Precision};

/// What to time.
pub struct FrameBenchOptions {
    /// A scene with a camera volume (its sidecar, or a built-in scene's).
    pub scene: String,
    /// The models: a design and who supplies its direct light.
    pub models: Vec<(Design, DirectLight)>,
    /// The precisions each model's networks run in (f16: GPU kernels only).
    pub precisions: Vec<Precision>,
    pub resolutions: Vec<[u32; 2]>,
    /// Timed frames per measurement, after one untimed; medians are reported.
    pub repeats: usize,
    /// Samples per pixel of traced direct light.
    pub direct_spp: u32,
    /// The lighting (a map file or built-in spec), turned by a different angle every frame so
    /// that each runs the encoder.
    pub map: String,
    /// Also time each kernel of a lighting change on the GPU (GPU kernels only).
    pub profile: bool,
}

/// One model at one resolution.
pub struct FrameBenchRow {
    pub label: String,
    pub resolution: [u32; 2],
    /// Pixels the networks shade.
    pub foreground: usize,
    /// Medians of a frame from a new viewpoint under a new lighting.
    pub frame: FrameTimings,
    /// Median of a lighting change under a still camera: the encoder and the shading networks.
    pub relight_ms: f64,
    /// Times a lighting change made the host wait for the GPU queue (None off the GPU kernels).
    pub relight_waits: Option<u64>,
    /// Medians of a whole frame from a new viewpoint and of a whole lighting change (direct
    /// light included) left on the device, not read back, as `nprt view` shows them (None off
    /// the GPU kernels).
    pub shown_ms: Option<[f64; 2]>,
    /// Where the networks ran.
    pub networks_on: String,
    /// Where the G-buffer was made.
    pub gbuffer_on: &'static str,
    /// Where traced direct light ran.
    pub paths_on: &'static str,
    /// With `profile`: each kernel's GPU time in a lighting change, longest first.
    #[cfg(feature = "gpu")]
    pub profile: Option<Vec<nprt_gpu::KernelTime>>,
}

/// Times every model at every resolution, calling `on_row` as each is done.
pub fn bench_frame(
    opts: &FrameBenchOptions,
    engine: Engine,
    mut on_row: impl FnMut(&FrameBenchRow),
) -> Result<()> {
    for &[w, h] in &opts.resolutions {
        engine
            .tracer()
            .check_frame(w, h, &format!("a {w}×{h} frame"))?;
    }
    let scene = load_scene(&opts.scene, &SceneOptions::default())?;
    let path = CameraPath::through_volume_of(
        None,
        &scene,
        &opts.scene,
        "bench frame places its camera in one",
    )?;
    let map = &nprt_scene::open_envmap(&opts.map)?;
    let (lo, hi) = scene.bounds();
    let ts = TraceScene::new(&scene);
    let runs = opts
        .models
        .iter()
        .flat_map(|&m| opts.precisions.iter().map(move |&p| (m, p)));
    for ((design, direct), precision) in runs {
        let bounds = [lo.to_array(), hi.to_array()];
        let (model, label) = untrained(design, direct, precision, bounds, engine)?;
        for &[w, h] in &opts.resolutions {
            let camera = path.camera(0.5, w, h);
            on_row(&time_frames(&model, &label, (&ts, &camera, map), opts)?);
        }
    }
    Ok(())
}

/// `model`'s frames of `camera` on `ts` under `map`, timed as [`bench_frame`] times them: a
/// new viewpoint and a lighting change under the still camera, `opts.repeats` times after an
/// untimed first, and where the host waits for the device, both again left on it.
fn time_frames(
    model: &Relighter,
    label: &str,
    (ts, camera, map): (&TraceScene, &Camera, &EnvMap),
    opts: &FrameBenchOptions,
) -> Result<FrameBenchRow> {
    let median = |v: Vec<f64>| nprt_net::median(v);
    let mut frames = Vec::new();
    let mut relights = Vec::new();
    let mut foreground = 0;
    let mut relight_waits = None;
    let mut shown = [Vec::new(), Vec::new()];
    // The last frame's lighting change, timed kernel by kernel.
    #[cfg(feature = "gpu")]
    let mut profile = None;
    for i in 0..=opts.repeats {
        let rotation = 10.0 * i as f32;
        let sampling = DirectSampling {
            spp: opts.direct_spp,
            seed: i as u64,
            denoiser: None,
        };
        // A new viewpoint under a new lighting: nothing kept from before.
        let mut cache = FrameCache::default();
        let (_, t) = model.frame(&mut cache, ts, camera, map, rotation, i, sampling)?;
        // A lighting change under the still camera.
        let turned = rotation + 5.0;
        let waits = model.host_waits();
        let (_, change) = model.frame(&mut cache, ts, camera, map, turned, i + 1, sampling)?;
        relight_waits = waits.zip(model.host_waits()).map(|(a, b)| b - a);
        foreground = cache.foreground();
        // Both again, left on the device as the viewer leaves them (after the profile,
        // which reads the kept lighting).
        #[cfg(feature = "gpu")]
        if opts.profile && i == opts.repeats {
            profile = model.profile_relight(&cache)?;
        }
        if waits.is_some() && i > 0 {
            let mut cache = FrameCache::default();
            for (k, turn) in [0.0, 5.0].into_iter().enumerate() {
                let lit = (map, rotation + turn, i + k);
                let (_, t) = model.frame_shown(&mut cache, ts, camera, lit, sampling, true)?;
                shown[k].push(t.total_ms());
            }
        }
        // The first frame is untimed: a GPU compiles and allocates on first use.
        if i > 0 {
            frames.push(t);
            relights.push(change.encoder_ms + change.network_ms);
        }
    }
    Ok(FrameBenchRow {
        label: label.to_string(),
        resolution: [camera.width, camera.height],
        foreground,
        frame: FrameTimings::median(&frames),
        relight_ms: median(relights),
        relight_waits,
        shown_ms: (!shown[0].is_empty()).then(|| shown.map(median)),
        networks_on: model.networks_on(),
        gbuffer_on: model.gbuffer_on(),
        paths_on: model.paths_on(),
        #[cfg(feature = "gpu")]
        profile,
    })
}

/// An untrained model of `design` (the cost does not depend on the weights) in `bounds`, on
/// `engine` in `precision`, and its row's label.
fn untrained(
    design: Design,
    direct: DirectLight,
    precision: Precision,
    bounds: [[f32; 3]; 2],
    engine: Engine,
) -> Result<(Relighter, String)> {
    let config = ModelConfig {
        direct,
        ..ModelConfig::new(design, None)
    };
    let net = config.build(&mut Init::new(1));
    let file = ModelFile::untrained(config.clone(), &net, bounds);
    let mut model = Relighter::new(file, net, engine)?;
    model.set_precision(precision)?;
    let label = match precision {
        Precision::F32 => config.label(),
        Precision::F16 => format!("{} f16", config.label()),
    };
    Ok((model, label))
}
