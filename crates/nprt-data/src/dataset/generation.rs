//! Rendering a planned dataset: views are rendered by whichever shard owns them (index mod N),
//! written atomically, and skipped on resume once they read back complete.

use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use nprt_scene::EnvMap;
use nprt_trace::{render, PixelFilter, RenderSettings, TraceScene};

use super::manifest::{load_manifest, Manifest, ViewRecord, MANIFEST};
use super::view_file::check_view;

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
