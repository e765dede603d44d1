//! A reference render of a scene as its file describes it: its own sensor, film, sampler and
//! integrator depth, with a box pixel filter, unless options override them (`nprt reference`).

use std::time::Instant;

use anyhow::{bail, Result};
use nprt_scene::{load_scene, open_envmap, Camera, SceneOptions};

use crate::frame::Frame;
use crate::render::{render, PixelFilter, RenderSettings};
use crate::trace_scene::TraceScene;

/// Samples per pixel when neither the options nor the scene name a count.
pub const DEFAULT_REFERENCE_SPP: u32 = 64;

/// What to render; `Default` renders the scene as it stands.
#[derive(Clone, Debug, Default)]
pub struct ReferenceOptions {
    /// `NAME=VALUE` overrides of Mitsuba `<default>` parameters.
    pub set: Vec<(String, String)>,
    /// A map spec lighting the scene instead of its own environment emitter.
    pub envmap: Option<String>,
    /// Rotation of the environment about +Y, degrees.
    pub rotate_deg: f32,
    /// The integrator's max_depth in Mitsuba's meaning (negative: unlimited); default the
    /// scene's.
    pub max_depth: Option<i64>,
    /// Film size (default the scene's).
    pub resolution: Option<[u32; 2]>,
    /// Samples per pixel (default the scene's sampler, else [`DEFAULT_REFERENCE_SPP`]).
    pub spp: Option<u32>,
    pub seed: u64,
    /// Every sample through the pixel centre (the dataset convention) instead of a box filter.
    pub centre: bool,
    pub progress: bool,
}

/// A finished reference render and what it took.
pub struct Reference {
    pub frame: Frame,
    pub camera: Camera,
    pub settings: RenderSettings,
    pub triangles: usize,
    /// Approximations and substitutions made, for the user.
    pub warnings: Vec<String>,
    pub load_s: f64,
    pub bvh_s: f64,
    pub render_s: f64,
}

impl Reference {
    pub fn samples_per_s(&self) -> f64 {
        let c = &self.camera;
        c.width as f64 * c.height as f64 * self.settings.spp as f64 / self.render_s.max(1e-9)
    }
}

/// Loads `scene` (any format `nprt_scene::load_scene` reads) and renders it.
pub fn render_reference(scene_spec: &str, opts: &ReferenceOptions) -> Result<Reference> {
    if opts.spp == Some(0) {
        bail!("samples per pixel must be at least 1");
    }
    let t0 = Instant::now();
    let scene = load_scene(
        scene_spec,
        &SceneOptions {
            set: opts.set.clone(),
            lighting_replaced: opts.envmap.is_some(),
        },
    )?;
    let mut warnings = scene.warnings.clone();
    let env = match (&opts.envmap, &scene.envmap) {
        (Some(spec), _) => open_envmap(spec)?,
        (None, Some(env)) => env.clone(),
        (None, None) => {
            bail!("scene '{scene_spec}' has no environment emitter; give one with --envmap")
        }
    }
    .rotated_y(opts.rotate_deg);
    warnings.extend(env.warnings());
    let mut camera = scene.camera.clone().unwrap_or_else(|| {
        warnings.push(format!(
            "scene '{scene_spec}' has no camera; framing its bounds from +Z"
        ));
        scene.framing_camera()
    });
    if let Some([w, h]) = opts.resolution {
        camera = camera.with_resolution(w, h);
    }
    Frame::check_size(
        camera.width,
        camera.height,
        &format!("a {}×{} frame", camera.width, camera.height),
    )?;
    let max_depth = match opts.max_depth {
        Some(d) => u32::try_from(d).ok(),
        None => scene.max_depth,
    };
    let settings = RenderSettings {
        spp: opts.spp.or(scene.spp).unwrap_or(DEFAULT_REFERENCE_SPP),
        max_depth,
        rr_depth: scene.rr_depth,
        seed: opts.seed,
        filter: if opts.centre {
            PixelFilter::Centre
        } else {
            PixelFilter::Box
        },
        progress: opts.progress,
    };
    let load_s = t0.elapsed().as_secs_f64();
    let ts = TraceScene::new(&scene);
    let bvh_s = t0.elapsed().as_secs_f64() - load_s;
    let t1 = Instant::now();
    let frame = render(&ts, &camera, &env, &settings);
    Ok(Reference {
        frame,
        camera,
        settings,
        triangles: scene.triangle_count(),
        warnings,
        load_s,
        bvh_s,
        render_s: t1.elapsed().as_secs_f64(),
    })
}
