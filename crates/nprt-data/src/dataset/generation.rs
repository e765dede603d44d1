//! Rendering a planned dataset: views are rendered by whichever shard owns them (index mod N),
//! written atomically, and skipped on resume once they read back complete.

use std::collections::{BTreeSet, HashSet};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use glam::Vec3;
use nprt_scene::EnvMap;
use nprt_trace::{Frame, PixelFilter, RenderSettings, Tracer};

use super::manifest::{load_manifest, Manifest, ViewRecord, MANIFEST};
use super::view_file::{check_view, write_view, ViewImage};

/// Creates the dataset folder and its manifest, or checks that an existing one was made with
/// the same settings. The tracer is not one: the CPU's and the GPU's agree within noise, so a
/// dataset either began is resumed (and trained on) with the other, its manifest naming the
/// first.
pub fn prepare(dir: &Path, manifest: &Manifest) -> Result<()> {
    check_not_model_folder(dir)?;
    std::fs::create_dir_all(dir.join("views"))
        .with_context(|| format!("cannot create dataset folder '{}'", dir.display()))?;
    if dir.join(MANIFEST).exists() {
        let existing = load_manifest(dir)?;
        let mut asked = manifest.clone();
        asked.settings.tracer = existing.settings.tracer;
        if existing != asked {
            let differences = existing.settings.differences(&asked.settings);
            let what = if differences.is_empty() {
                "a different camera or lighting plan".to_string()
            } else {
                format!("other settings: {}", differences.join(", "))
            };
            bail!(
                "'{}' holds a dataset made with {what}; use another --out folder or the same settings",
                dir.display()
            );
        }
        return Ok(());
    }
    let text = serde_json::to_string_pretty(manifest)?;
    nprt_io::write_file(&dir.join(MANIFEST), &text)
}

/// What a training run writes into its model folder (nprt-net's and Deep Shading's config,
/// weights and checkpoint; nprt-net's tests hold the names to its own).
pub const MODEL_FOLDER_ENTRIES: [&str; 4] = [
    "model.json",
    "deep-shading.json",
    "weights.safetensors",
    "checkpoint",
];

/// Refuses a dataset folder that holds a model, as `nprt train` refuses a model folder that
/// holds a dataset: views written beside a model left a folder neither command could use.
pub fn check_not_model_folder(dir: &Path) -> Result<()> {
    if let Some(entry) = MODEL_FOLDER_ENTRIES.iter().find(|e| dir.join(e).exists()) {
        bail!(
            "'{}' is a model folder (it holds {entry}); a dataset goes into a folder of its own \
             (--out)",
            dir.display()
        );
    }
    Ok(())
}

/// Salt of the second half's random streams of a view rendered in halves.
const SECOND_HALF: u64 = 0x9e37_79b9_7f4a_7c15;

/// Salt of the transfer vectors' paths (BSDF-sampled, apart from the radiance's).
const TRANSFER_PATHS: u64 = 0x7a4e_5f3e_c0ef_f1c1;

/// Renders one view to its file: a test view of a dataset with `test_spp` as two independent
/// halves, averaged, the first kept apart; a training view of a dataset with `--transfer`
/// with its transfer vectors, from as many paths per pixel as its radiance.
pub fn render_view(
    tracer: &Tracer,
    maps: &[EnvMap],
    manifest: &Manifest,
    view: &ViewRecord,
    dir: &Path,
) -> Result<()> {
    let s = &manifest.settings;
    let env = view.lighting(maps)?;
    let settings = RenderSettings {
        spp: s.spp_of(view),
        max_depth: s.max_depth,
        rr_depth: s.rr_depth,
        seed: view.seed,
        filter: PixelFilter::Centre,
        progress: false,
    };
    let image = if s.in_halves(view) {
        let half = |seed| {
            tracer.render(
                &view.camera(),
                &env,
                &RenderSettings {
                    spp: settings.spp / 2,
                    seed,
                    ..settings.clone()
                },
            )
        };
        let (first, second) = (half(view.seed)?, half(view.seed ^ SECOND_HALF)?);
        let mean = |a: &[Vec3], b: &[Vec3]| a.iter().zip(b).map(|(x, y)| (*x + *y) * 0.5).collect();
        let frame = Frame {
            width: first.width,
            height: first.height,
            radiance: mean(&first.radiance, &second.radiance),
            direct: mean(&first.direct, &second.direct),
            gbuffer: first.gbuffer,
        };
        ViewImage {
            frame,
            half: Some(first.radiance),
            transfer: None,
        }
    } else {
        ViewImage {
            frame: tracer.render(&view.camera(), &env, &settings)?,
            half: None,
            transfer: None,
        }
    };
    let transfer = match s.parts(view).transfer {
        None => None,
        Some(basis) => {
            let Some(ts) = tracer.cpu_scene() else {
                bail!(
                    "transfer vectors are recorded by the CPU tracer only; generate with \
                     --device cpu"
                );
            };
            let seed = view.seed ^ TRANSFER_PATHS;
            let t = basis.record(ts, &view.camera(), &RenderSettings { seed, ..settings });
            nprt_io::interrupt::check()?;
            Some(t)
        }
    };
    write_view(&dir.join(&view.file), &ViewImage { transfer, ..image })
}

#[derive(Debug, Default)]
pub struct Summary {
    pub rendered: u64,
    pub skipped: u64,
    pub redone: Vec<String>,
    /// Temporary files of this shard's views that killed runs left behind, now removed.
    pub removed_temporaries: usize,
    pub seconds: f64,
    pub samples: f64,
}

/// Renders every view of shard `shard.0` of `shard.1` that is not yet complete on disk, with
/// `tracer` (whichever began the dataset: see [`prepare`]).
pub fn run(
    tracer: &Tracer,
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
    let mut summary = Summary {
        removed_temporaries: remove_leftovers(dir, &mine)?,
        ..Summary::default()
    };
    for v in mine {
        let path = dir.join(&v.file);
        match path
            .exists()
            .then(|| check_view(&path, v, manifest.settings.parts(v)))
        {
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
        render_view(tracer, maps, manifest, v, dir)
            .with_context(|| format!("view {} ({})", v.index, v.file))?;
        summary.rendered += 1;
        summary.samples += v.width as f64 * v.height as f64 * manifest.settings.spp_of(v) as f64;
        bar.inc(1);
    }
    bar.finish_and_clear();
    summary.seconds = t0.elapsed().as_secs_f64();
    Ok(summary)
}

/// Removes the temporary files that killed runs left for `views` (another shard's are not
/// ours to touch: it may be writing them now).
fn remove_leftovers(dir: &Path, views: &[&ViewRecord]) -> Result<usize> {
    let mine: HashSet<PathBuf> = views.iter().map(|v| dir.join(&v.file)).collect();
    let folders: BTreeSet<&Path> = mine.iter().filter_map(|p| p.parent()).collect();
    let mut removed = 0;
    for folder in folders {
        removed += nprt_io::remove_temporaries(folder, |target| mine.contains(target))?;
    }
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::plan::room_request;
    use crate::dataset::{plan, read_view, Request, ViewSpec};
    use nprt_scene::{load_scene, SceneOptions};
    use nprt_trace::{render, TraceScene};

    fn mse(a: &[Vec3], b: &[Vec3]) -> f64 {
        let sum: f64 = a
            .iter()
            .zip(b)
            .map(|(x, y)| (*x - *y).length_squared() as f64)
            .sum();
        sum / (3 * a.len()) as f64
    }

    /// A test view rendered in halves holds their mean and the first half apart, and the first
    /// half's distance to the whole is the whole's own noise (its distance to a converged image).
    #[test]
    fn test_views_in_halves_hold_their_own_noise() {
        let scene = load_scene("builtin:room", &SceneOptions::default()).unwrap();
        let ts = TraceScene::new(&scene);
        let base = room_request(&scene, ["builtin:indoor:1", "builtin:indoor:2"]);
        let request = Request {
            views: ViewSpec {
                test_resolution: [32, 32],
                test_spp: 8,
                ..base.views
            },
            ..base
        };
        let manifest = plan(&request, &ts).unwrap();
        let dir = std::env::temp_dir().join(format!("nprt-halves-{}", std::process::id()));
        prepare(&dir, &manifest).unwrap();
        run(
            &Tracer::Cpu(&ts),
            &request.maps,
            &manifest,
            &dir,
            (0, 1),
            false,
        )
        .unwrap();
        let view = |split: &str| manifest.views.iter().find(|v| v.split == split).unwrap();
        let (train, test) = (view("train"), view("test"));
        assert!(!manifest.settings.in_halves(train) && manifest.settings.in_halves(test));
        let train_file = dir.join(&train.file);
        assert!(read_view(&train_file, train, Default::default())
            .unwrap()
            .half
            .is_none());
        let err = read_view(&train_file, train, manifest.settings.parts(test))
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains("half.R"), "{err}");

        let image = read_view(&dir.join(&test.file), test, manifest.settings.parts(test)).unwrap();
        let (whole, half) = (&image.frame.radiance, image.half.unwrap());
        let env = test.lighting(&request.maps).unwrap();
        let at = |spp, seed| RenderSettings {
            spp,
            max_depth: scene.max_depth,
            rr_depth: scene.rr_depth,
            seed,
            filter: PixelFilter::Centre,
            progress: false,
        };
        let second = render(&ts, &test.camera(), &env, &at(4, test.seed ^ SECOND_HALF));
        for ((w, a), b) in whole.iter().zip(&half).zip(&second.radiance) {
            assert!((*w - (*a + *b) * 0.5).abs().max_element() <= 1e-6 * (1.0 + w.max_element()));
        }
        let converged = render(&ts, &test.camera(), &env, &at(2048, 99));
        let (floor, actual) = (mse(&half, whole), mse(whole, &converged.radiance));
        assert!(
            actual > 0.0 && (floor / actual - 1.0).abs() < 0.35,
            "floor {floor}, actual {actual}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
