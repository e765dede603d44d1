//! Each stage of an experiment, resumable: the dataset and the trainings resume themselves
//! (nprt-data and nprt-net keep their settings and progress), and the evaluations are cached
//! under a key of everything they read, so a killed or repeated run redoes only what changed.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use nprt_data::generate;
use nprt_eval::{evaluate, score_networks, write_report, EvalOptions, Evaluation, MethodResult};
use nprt_net::deep_shading::{self, DeepShadingOptions};
use nprt_net::model::folder::{CONFIG_FILE, WEIGHTS_FILE};
use nprt_net::training::training_set::TrainingSet;
use nprt_net::{Engine, ModelConfig, TrainOptions, TrainSummary, RECIPE};
use nprt_render::oidn::Oidn;
use nprt_render::{RenderJob, RenderOptions};

use crate::experiment::{calibration, Experiment};
use crate::readback::{self, Ablation, GrowthPoint};

/// Renders (or resumes) the dataset; whether any view was rendered.
pub fn dataset(x: &Experiment, data: &Path) -> Result<bool> {
    let s = generate(&x.generate_options(data), |p| {
        for w in &p.warnings {
            eprintln!("warning: {w}");
        }
    })?;
    println!(
        "dataset '{}': {} views rendered in {:.1} s ({:.3} Msamples/s), {} already complete",
        data.display(),
        s.rendered,
        s.seconds,
        s.samples / s.seconds.max(1e-9) / 1e6,
        s.skipped
    );
    Ok(s.rendered > 0)
}

/// Trains (or resumes, or finds finished) one Neural PRT model; whether it trained.
pub fn train_model(x: &Experiment, data: &Path, config: &ModelConfig, out: &Path) -> Result<bool> {
    let set = TrainingSet::load(data, config, true, |why| eprintln!("{why}"))?;
    let mut opts = TrainOptions::default().with_run(config.design, x.training(), None);
    opts.calibration = calibration(config);
    // The recipe's model on the dataset's transfer vectors, where it has them.
    if *config == RECIPE.config() {
        opts.targets = RECIPE.targets(config, set.manifest.settings.transfer);
    }
    // The paper's four designs keep their models as training grows (`--snapshots`).
    if x.snapshot_configs().contains(config) {
        opts.schedule.snapshots = x.snapshots.clone();
    }
    let (s, _) = nprt_net::train(
        &set,
        config,
        &opts,
        out,
        x.engine,
        nprt_net::Watch::default(),
    )?;
    report_training(&config.label(), &s, out);
    Ok(s.split.steps > 0.0)
}

/// Trains (or resumes) the Deep Shading U-Net; whether it trained.
pub fn train_deep_shading(x: &Experiment, data: &Path, out: &Path) -> Result<bool> {
    let defaults = DeepShadingOptions::default();
    let opts = DeepShadingOptions {
        schedule: x.deep_shading_training().apply(defaults.schedule.clone()),
        ..defaults
    };
    let (s, _) = deep_shading::train(data, &opts, x.engine, out, nprt_net::Watch::default())?;
    report_training("deep-shading", &s, out);
    Ok(s.split.steps > 0.0)
}

fn report_training(name: &str, s: &TrainSummary, out: &Path) {
    println!(
        "{name}: {:.2} epochs, {} steps in {:.1} s of training ({:.0} K samples/s on {}); validation loss {:.5}; model in '{}'",
        s.epochs,
        s.steps,
        s.seconds,
        s.samples as f64 / s.seconds.max(1e-9) / 1e3,
        s.steps_on,
        s.final_val,
        out.display()
    );
}

/// The evaluation options the budget sets.
pub fn eval_options(x: &Experiment, data: &Path, models: &[PathBuf]) -> EvalOptions {
    let b = &x.budget;
    EvalOptions {
        data: data.to_path_buf(),
        models: models.to_vec(),
        sh_spp: b.sh_spp,
        timing_res: b.timing_res,
        temporal_frames: b.temporal.0,
        temporal_res: b.temporal.1,
        ..EvalOptions::default()
    }
}

/// The evaluation against every baseline, written as a report in `report`, or the one a
/// previous run wrote there from the same inputs; whether it ran. The kept one is taken only
/// where its key holds the inputs and its outputs as this run wrote them (results.json and
/// the pictures): a report rewritten by hand (`nprt eval --out` into the same folder) or with
/// pictures gone is made again.
pub fn evaluation(engine: Engine, opts: &EvalOptions, report: &Path) -> Result<(Evaluation, bool)> {
    let inputs = inputs_key(engine, opts)?;
    let key_file = report.join("evaluation.key");
    let results = report.join("results.json");
    let kept = read_key(&key_file);
    if kept.as_deref() == Some(format!("{inputs}\n{}", outputs_key(report)).as_str()) {
        match held(&results, opts) {
            Ok(e) => {
                println!(
                    "evaluation: as '{}' holds it (its inputs are unchanged)",
                    results.display()
                );
                return Ok((e, false));
            }
            Err(e) => eprintln!("evaluating again: {e:#}"),
        }
    }
    let e = evaluate(opts, engine)?;
    let (md, _) = write_report(&e, report)?;
    let key = format!("{inputs}\n{}", outputs_key(report));
    nprt_io::write_file(&key_file, &key)?;
    println!("evaluation report: '{}'", md.display());
    Ok((e, true))
}

/// Table 2's runs scored on the test views (`score_networks`), kept in `file` with the key of
/// their inputs; whether they were scored now.
pub fn ablation(
    x: &Experiment,
    opts: &EvalOptions,
    file: &Path,
) -> Result<(Vec<MethodResult>, bool)> {
    let key = inputs_key(x.engine, opts)?;
    if let Ok(a) = read(file).and_then(|bytes| readback::ablation(&bytes, file)) {
        if a.key == key {
            return Ok((a.rows, false));
        }
    }
    let rows = score_networks(opts, x.engine)?;
    let scored = Ablation { key, rows };
    nprt_io::write_file(file, serde_json::to_vec_pretty(&scored)?)?;
    Ok((scored.rows, true))
}

/// The paper's four designs as kept at each snapshot point, scored on the test views, kept in
/// `file` per point with the key of its inputs (a point whose models changed is scored again);
/// whether any point was scored now. Points no design kept are left out.
pub fn snapshots(x: &Experiment, data: &Path, file: &Path) -> Result<(Vec<GrowthPoint>, bool)> {
    let kept: Vec<GrowthPoint> = read(file)
        .and_then(|bytes| readback::growth(&bytes, file))
        .unwrap_or_default();
    let (mut points, mut worked) = (Vec::new(), false);
    for point in &x.snapshots {
        let dirs: Vec<PathBuf> = (x.snapshot_configs().iter())
            .map(|c| point.dir(&x.model_dir(c)))
            .filter(|d| d.join(WEIGHTS_FILE).is_file())
            .collect();
        if dirs.is_empty() {
            continue;
        }
        let opts = eval_options(x, data, &dirs);
        let key = inputs_key(x.engine, &opts)?;
        if let Some(p) = kept.iter().find(|p| p.key == key) {
            points.push(p.clone());
            continue;
        }
        let minutes = dirs
            .iter()
            .map(|d| training_seconds(d).map(|s| s / 60.0))
            .sum::<Result<f64>>()?
            / dirs.len() as f64;
        let rows = score_networks(&opts, x.engine)?;
        points.push(GrowthPoint {
            point: point.to_string(),
            key,
            minutes,
            rows,
        });
        worked = true;
        nprt_io::write_file(file, serde_json::to_vec_pretty(&points)?)?;
    }
    Ok((points, worked))
}

/// The training time a model folder's model.json records, seconds.
fn training_seconds(model: &Path) -> Result<f64> {
    let file = nprt_net::model::folder::read_model_file(model)?;
    (file.trained_seconds())
        .with_context(|| format!("'{}' records no training time", model.display()))
}

/// A camera path relit by `model` under the dataset's held-out maps, into `frames`.
pub fn relight(x: &Experiment, data: &Path, model: &Path, frames: &Path) -> Result<()> {
    let manifest = nprt_data::dataset::load_manifest(data)?;
    let s = &manifest.settings;
    let held_out: Vec<&str> = s
        .test_maps
        .iter()
        .map(|&k| s.envmaps[k].spec.as_str())
        .collect();
    let (count, side) = x.budget.relight;
    let job = RenderJob::prepare(
        &RenderOptions {
            model: model.to_path_buf(),
            out: frames.to_path_buf(),
            camera_volume: x.camera.file.clone(),
            lighting: held_out.join(","),
            frames: count,
            resolution: [side; 2],
            ..RenderOptions::default()
        },
        x.engine,
    )?;
    let done = job.run(|_| {})?;
    println!(
        "{count} frames at {side}² in '{}' ({:.1} ms per frame), animation '{}'",
        done.frames_dir.display(),
        done.mean.total_ms(),
        done.animation.path().display()
    );
    Ok(())
}

/// A key of everything an evaluation reads: the dataset's manifest, each model's files, the
/// options, the engine and whether OIDN is there.
fn inputs_key(engine: Engine, opts: &EvalOptions) -> Result<String> {
    let mut h = blake3::Hasher::new();
    h.update(&read(&opts.data.join("manifest.json"))?);
    for dir in opts.models.iter().chain(&opts.deep_shading) {
        for file in [CONFIG_FILE, deep_shading::CONFIG_FILE, WEIGHTS_FILE] {
            let path = dir.join(file);
            if path.is_file() {
                h.update(file.as_bytes());
                h.update(&read(&path)?);
            }
        }
    }
    h.update(format!("{opts:?} {} {}", engine.name(), Oidn::open().is_ok()).as_bytes());
    Ok(h.finalize().to_hex().to_string())
}

/// What a report folder's evaluation wrote, by content: results.json, report.md and every
/// picture report.md shows (the paper's report adds pictures of its own to the same folder).
fn outputs_key(report: &Path) -> String {
    let mut h = blake3::Hasher::new();
    let md = std::fs::read_to_string(report.join("report.md")).unwrap_or_default();
    h.update(&std::fs::read(report.join("results.json")).unwrap_or_default());
    h.update(md.as_bytes());
    for picture in md
        .split("](")
        .skip(1)
        .filter_map(|rest| rest.split(')').next())
    {
        h.update(picture.as_bytes());
        // A picture gone hashes as no bytes: the key then differs.
        h.update(&std::fs::read(report.join(picture)).unwrap_or_default());
    }
    h.finalize().to_hex().to_string()
}

/// `e` read back, refused unless it is the evaluation `opts` asks for: every model's row and
/// every method's figures on the dataset's test views (as many as `opts` evaluates), each
/// finite.
/// The evaluation `results` keeps, where it is this run's: as many test views as the run
/// evaluates, and a finite figure for each.
fn held(results: &Path, opts: &EvalOptions) -> Result<Evaluation> {
    let manifest = nprt_data::dataset::load_manifest(&opts.data)?;
    let test_views = manifest.settings.test_views as usize;
    let views = opts.max_views.map_or(test_views, |n| n.min(test_views));
    readback::evaluation(&read(results)?, results, views, opts.models.len())
}

fn read(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).with_context(|| format!("cannot read '{}'", path.display()))
}

fn read_key(path: &Path) -> Option<String> {
    std::fs::read_to_string(path).ok()
}
