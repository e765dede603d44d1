//! The dataset on disk (format documented in docs/dataset.md): `manifest.json` and one OpenEXR
//! per view under `views/`. The manifest is a pure function of the settings, so every shard
//! computes the same one; views are rendered by whichever shard owns them (index mod N), written
//! atomically, and skipped on resume once they read back complete.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use glam::Mat4;
use nprt_scene::{Camera, CameraVolume, EnvMap, FovAxis, Scene};
use nprt_trace::exr_io::read_channels;
use nprt_trace::{render, Frame, PixelFilter, RenderSettings, TraceScene};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use crate::cameras::place_camera;

pub const FORMAT_VERSION: u32 = 1;
pub const MANIFEST: &str = "manifest.json";

/// Everything that determines a dataset's content; two runs agree on it or must not share a folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    pub format_version: u32,
    pub scene: String,
    /// BLAKE3 of the loaded geometry and the scene source (see [`scene_hash`]).
    pub scene_hash: String,
    pub envmaps: Vec<MapRecord>,
    pub train_maps: Vec<usize>,
    pub test_maps: Vec<usize>,
    pub train_views: u64,
    pub test_views: u64,
    pub train_resolution: [u32; 2],
    pub test_resolution: [u32; 2],
    pub spp: u32,
    pub max_depth: Option<u32>,
    pub rr_depth: u32,
    pub seed: u64,
    pub camera_volume: VolumeRecord,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MapRecord {
    /// File path or built-in spec, as given.
    pub spec: String,
    /// BLAKE3 of the file's bytes (of the spec for built-in maps).
    pub hash: String,
    pub width: usize,
    pub height: usize,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VolumeRecord {
    pub min: [f32; 3],
    pub max: [f32; 3],
    pub look: [f32; 3],
    pub spread_deg: f32,
    pub fov_deg: f32,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViewRecord {
    pub index: u64,
    /// "train" or "test".
    pub split: String,
    /// Relative to the dataset folder.
    pub file: String,
    /// Camera-to-world, column-major, Mitsuba's camera convention (+Z forward, +Y up, +X left).
    pub camera_to_world: [f32; 16],
    /// Horizontal field of view, degrees.
    pub fov_x_deg: f32,
    pub width: u32,
    pub height: u32,
    /// Index into `settings.envmaps`.
    pub map: usize,
    /// Rotation of the map about +Y, degrees.
    pub rotation_deg: f32,
    /// Seed of the view's per-pixel random streams.
    pub seed: u64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub settings: Settings,
    /// Scene bounds (min, max) for normalising positions to [-1, 1].
    pub bounds: [[f32; 3]; 2],
    pub views: Vec<ViewRecord>,
}

impl Manifest {
    /// Parses and [checks](Manifest::check) a manifest's JSON.
    pub fn from_json(bytes: &[u8]) -> Result<Manifest> {
        let manifest: Manifest = serde_json::from_slice(bytes).context("not a valid manifest")?;
        manifest.check()?;
        Ok(manifest)
    }

    /// Refuses a manifest that a hand edit or another tool made inconsistent, so that every
    /// later use (map indices, image sizes, cameras, file names) can trust it.
    pub fn check(&self) -> Result<()> {
        let s = &self.settings;
        if s.format_version != FORMAT_VERSION {
            bail!(
                "format_version is {}, this nprt reads {FORMAT_VERSION}",
                s.format_version
            );
        }
        let maps = s.envmaps.len();
        if let Some(&i) = s
            .train_maps
            .iter()
            .chain(&s.test_maps)
            .find(|&&i| i >= maps)
        {
            bail!("map index {i} is out of range: settings.envmaps lists {maps} maps");
        }
        if s.train_maps.is_empty() || s.test_maps.is_empty() {
            bail!("settings.train_maps and settings.test_maps must each name at least one map");
        }
        if !self.bounds.iter().flatten().all(|v| v.is_finite())
            || (0..3).any(|k| self.bounds[0][k] > self.bounds[1][k])
        {
            bail!("bounds {:?} are not a finite box (min ≤ max)", self.bounds);
        }
        for v in &self.views {
            let what = format!("view {} ('{}')", v.index, v.file);
            let allowed = match v.split.as_str() {
                "train" => &s.train_maps,
                "test" => &s.test_maps,
                other => bail!("{what}: split '{other}' is neither 'train' nor 'test'"),
            };
            if !allowed.contains(&v.map) {
                bail!(
                    "{what}: map {} is not one of its split's maps {allowed:?}",
                    v.map
                );
            }
            if v.width == 0 || v.height == 0 || v.width as u64 * v.height as u64 > 1 << 28 {
                bail!(
                    "{what}: size {}×{} is empty or implausibly large",
                    v.width,
                    v.height
                );
            }
            if !(v.fov_x_deg > 0.0 && v.fov_x_deg < 180.0) {
                bail!("{what}: fov_x_deg {} is not in (0, 180)", v.fov_x_deg);
            }
            if !v.camera_to_world.iter().all(|x| x.is_finite()) || !v.rotation_deg.is_finite() {
                bail!("{what}: camera_to_world or rotation_deg holds a non-finite number");
            }
            let file = Path::new(&v.file);
            if file.is_absolute()
                || file
                    .components()
                    .any(|c| matches!(c, std::path::Component::ParentDir))
            {
                bail!("{what}: file must be a path inside the dataset folder");
            }
        }
        Ok(())
    }
}

impl ViewRecord {
    pub fn camera(&self) -> Camera {
        Camera {
            to_world: Mat4::from_cols_array(&self.camera_to_world),
            fov_deg: self.fov_x_deg,
            fov_axis: FovAxis::X,
            width: self.width,
            height: self.height,
        }
    }
}

/// Source bytes that identify a scene: the file's bytes, or the built-in name.
pub fn scene_source(spec: &str) -> Result<Vec<u8>> {
    if spec.starts_with("builtin:") {
        Ok(spec.as_bytes().to_vec())
    } else {
        std::fs::read(spec).with_context(|| format!("cannot read scene '{spec}'"))
    }
}

/// Loads the scene `spec` and checks it is the one with hash `expected` (that a dataset was
/// rendered from, or a model trained on, as `what` says).
pub fn load_checked_scene(spec: &str, expected: &str, what: &str) -> Result<Scene> {
    let scene = nprt_scene::load_scene(spec, &nprt_scene::SceneOptions::default())?;
    let hash = scene_hash(&scene, &scene_source(spec)?);
    if hash != expected {
        bail!(
            "scene '{spec}' is not the scene {what} (hash {} ≠ {})",
            &hash[..12],
            &expected[..12.min(expected.len())]
        );
    }
    Ok(scene)
}

/// Hash of what the network will learn: geometry, material parameters at vertices, and the
/// scene's source text (file bytes, or the built-in name).
pub fn scene_hash(scene: &Scene, source: &[u8]) -> String {
    let mut h = blake3::Hasher::new();
    h.update(source);
    for m in &scene.meshes {
        for p in &m.positions {
            h.update(&p.x.to_le_bytes())
                .update(&p.y.to_le_bytes())
                .update(&p.z.to_le_bytes());
        }
        for t in &m.indices {
            t.iter().for_each(|i| {
                h.update(&i.to_le_bytes());
            });
        }
        let mat = &scene.materials[m.material];
        for uv in m
            .uvs
            .iter()
            .take(64)
            .chain(std::iter::once(&glam::Vec2::ZERO))
        {
            let p = mat.eval(*uv);
            for v in [p.kd.x, p.kd.y, p.kd.z, p.ks.x, p.ks.y, p.ks.z, p.alpha] {
                h.update(&v.to_le_bytes());
            }
        }
    }
    h.finalize().to_hex().to_string()
}

/// What a run of `generate` is asked to do.
pub struct Request<'a> {
    pub scene_spec: String,
    pub scene: &'a Scene,
    pub scene_source: Vec<u8>,
    pub volume: CameraVolume,
    pub map_specs: Vec<String>,
    pub maps: Vec<EnvMap>,
    pub test_maps: usize,
    pub train_views: u64,
    pub test_views: u64,
    pub train_resolution: [u32; 2],
    pub test_resolution: [u32; 2],
    pub spp: u32,
    pub seed: u64,
}

/// Builds the manifest: cameras, maps and rotations of every view, from the settings alone.
pub fn plan(req: &Request, ts: &TraceScene) -> Result<Manifest> {
    let (train_maps, test_maps) = crate::lighting::split(req.maps.len(), req.test_maps, req.seed)?;
    let envmaps = req
        .map_specs
        .iter()
        .zip(&req.maps)
        .map(|(spec, map)| {
            let hash = crate::lighting::map_hash(spec)?;
            Ok(MapRecord {
                spec: spec.clone(),
                hash,
                width: map.width(),
                height: map.height(),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let v = &req.volume;
    let settings = Settings {
        format_version: FORMAT_VERSION,
        scene: req.scene_spec.clone(),
        scene_hash: scene_hash(req.scene, &req.scene_source),
        envmaps,
        train_maps: train_maps.clone(),
        test_maps: test_maps.clone(),
        train_views: req.train_views,
        test_views: req.test_views,
        train_resolution: req.train_resolution,
        test_resolution: req.test_resolution,
        spp: req.spp,
        max_depth: req.scene.max_depth,
        rr_depth: req.scene.rr_depth,
        seed: req.seed,
        camera_volume: VolumeRecord {
            min: v.min.into(),
            max: v.max.into(),
            look: v.look.into(),
            spread_deg: v.spread_deg,
            fov_deg: v.fov_deg,
        },
    };
    let mut views = Vec::with_capacity((req.train_views + req.test_views) as usize);
    for index in 0..req.train_views + req.test_views {
        let train = index < req.train_views;
        let (split, local, pool, [w, h]) = if train {
            ("train", index, &train_maps, req.train_resolution)
        } else {
            (
                "test",
                index - req.train_views,
                &test_maps,
                req.test_resolution,
            )
        };
        let mut rng = Pcg64Mcg::seed_from_u64(
            req.seed
                .wrapping_add(0x1f83_d9ab_fb41_bd6b)
                .wrapping_mul(index + 1),
        );
        let map = pool[(rng.random::<u64>() % pool.len() as u64) as usize];
        let rotation_deg = rng.random::<f32>() * 360.0;
        let seed = rng.random::<u64>();
        let camera = place_camera(ts, &req.volume, req.seed, index, w, h)?;
        views.push(ViewRecord {
            index,
            split: split.into(),
            file: format!("views/{split}_{local:05}.exr"),
            camera_to_world: camera.to_world.to_cols_array(),
            fov_x_deg: camera.fov_deg,
            width: w,
            height: h,
            map,
            rotation_deg,
            seed,
        });
    }
    let (lo, hi) = req.scene.bounds();
    let manifest = Manifest {
        settings,
        bounds: [lo.into(), hi.into()],
        views,
    };
    manifest
        .check()
        .with_context(|| format!("cannot plan a dataset for scene '{}'", req.scene_spec))?;
    Ok(manifest)
}

pub fn load_manifest(dir: &Path) -> Result<Manifest> {
    Ok(load_manifest_hashed(dir)?.0)
}

/// The manifest of the dataset in `dir` and the dataset's hash (of the manifest's bytes, which
/// fix every view's camera, map, rotation and seed); models record it to refuse other data.
pub fn load_manifest_hashed(dir: &Path) -> Result<(Manifest, String)> {
    let path = dir.join(MANIFEST);
    let bytes =
        std::fs::read(&path).with_context(|| format!("cannot read '{}'", path.display()))?;
    let manifest = Manifest::from_json(&bytes)
        .with_context(|| format!("'{}' is not a usable nprt dataset manifest", path.display()))?;
    Ok((manifest, blake3::hash(&bytes).to_hex().to_string()))
}

/// Creates the dataset folder and its manifest, or checks that an existing one was made with
/// the same settings.
pub fn prepare(dir: &Path, manifest: &Manifest) -> Result<()> {
    std::fs::create_dir_all(dir.join("views"))
        .with_context(|| format!("cannot create dataset folder '{}'", dir.display()))?;
    if dir.join(MANIFEST).exists() {
        let existing = load_manifest(dir)?;
        if existing != *manifest {
            let what = if existing.settings != manifest.settings {
                "different settings"
            } else {
                "a different camera or lighting plan"
            };
            bail!(
                "'{}' holds a dataset made with {what}; use another --out folder or the same settings (existing: {})",
                dir.display(),
                serde_json::to_string(&existing.settings)?
            );
        }
        return Ok(());
    }
    let text = serde_json::to_string_pretty(manifest)?;
    nprt_io::write_file(&dir.join(MANIFEST), &text)
}

/// Checks that a view file reads back complete: right size, every channel, finite values.
pub fn check_view(path: &Path, view: &ViewRecord) -> Result<()> {
    read_view(path, view).map(|_| ())
}

/// Reads a view file, refusing one whose size disagrees with its record, that lacks a channel
/// or that holds non-finite values.
pub fn read_view(path: &Path, view: &ViewRecord) -> Result<Frame> {
    let (w, h, ch) = read_channels(path)?;
    if (w, h) != (view.width as usize, view.height as usize) {
        bail!("is {w}×{h}, expected {}×{}", view.width, view.height);
    }
    Frame::from_channels(w, h, &ch)
}

/// Renders one view to its file.
pub fn render_view(
    ts: &TraceScene,
    maps: &[EnvMap],
    manifest: &Manifest,
    view: &ViewRecord,
    dir: &Path,
) -> Result<()> {
    let s = &manifest.settings;
    let env = maps[view.map].rotated_y(view.rotation_deg);
    let settings = RenderSettings {
        spp: s.spp,
        max_depth: s.max_depth,
        rr_depth: s.rr_depth,
        seed: view.seed,
        filter: PixelFilter::Centre,
        progress: false,
    };
    let frame = render(ts, &view.camera(), &env, &settings);
    frame.write_exr(&dir.join(&view.file))
}

#[derive(Debug, Default)]
pub struct Summary {
    pub rendered: u64,
    pub skipped: u64,
    pub redone: Vec<String>,
    pub seconds: f64,
    pub samples: f64,
}

/// Renders every view of shard `shard.0` of `shard.1` that is not yet complete on disk.
pub fn run(
    ts: &TraceScene,
    maps: &[EnvMap],
    manifest: &Manifest,
    dir: &Path,
    shard: (u64, u64),
    progress: bool,
) -> Result<Summary> {
    let mine: Vec<&ViewRecord> = manifest
        .views
        .iter()
        .filter(|v| v.index % shard.1 == shard.0)
        .collect();
    let mut todo = vec![];
    let mut summary = Summary::default();
    for v in mine {
        let path = dir.join(&v.file);
        match path.exists().then(|| check_view(&path, v)) {
            Some(Ok(())) => summary.skipped += 1,
            Some(Err(e)) => {
                summary.redone.push(format!("{}: {e:#}", v.file));
                todo.push(v);
            }
            None => todo.push(v),
        }
    }
    let bar = nprt_io::progress_bar(progress, todo.len() as u64, "generating", "views");
    let t0 = Instant::now();
    for v in todo {
        render_view(ts, maps, manifest, v, dir)
            .with_context(|| format!("view {} ({})", v.index, v.file))?;
        summary.rendered += 1;
        summary.samples += v.width as f64 * v.height as f64 * manifest.settings.spp as f64;
        bar.inc(1);
    }
    bar.finish_and_clear();
    summary.seconds = t0.elapsed().as_secs_f64();
    Ok(summary)
}

/// Completeness of a dataset folder.
#[derive(Debug, Default)]
pub struct Report {
    pub views: usize,
    pub complete: usize,
    pub missing: Vec<String>,
    pub corrupt: Vec<String>,
}

/// Reads every view back fully (in parallel: this is also how fast a trainer can load them).
pub fn verify(dir: &Path) -> Result<Report> {
    use rayon::prelude::*;
    let manifest = load_manifest(dir)?;
    let states: Vec<Result<(), String>> = manifest
        .views
        .par_iter()
        .map(|v| {
            let path: PathBuf = dir.join(&v.file);
            if !path.exists() {
                return Err(String::new());
            }
            check_view(&path, v).map_err(|e| format!("{e:#}"))
        })
        .collect();
    let mut report = Report {
        views: manifest.views.len(),
        ..Default::default()
    };
    for (v, state) in manifest.views.iter().zip(states) {
        match state {
            Ok(()) => report.complete += 1,
            Err(e) if e.is_empty() => report.missing.push(v.file.clone()),
            Err(e) => report.corrupt.push(format!("{}: {e}", v.file)),
        }
    }
    Ok(report)
}
