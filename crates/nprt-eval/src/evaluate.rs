//! The paper's evaluation: every trained design and every baseline on the dataset's test views
//! (held-out lighting), their errors, the error analysis against directness and specularity,
//! and timings at a fixed resolution (the paper's Tables 3 and 4).

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;

use anyhow::{bail, Result};
use nprt_data::dataset::Manifest;
use nprt_data::dataset::{load_checked_scene, load_manifest_hashed};
use nprt_data::views::{load_views, ImageView};
use nprt_net::training::training_set::open_recorded_map;
use nprt_net::Engine;
use nprt_render::oidn::Oidn;
use nprt_render::DirectSampling;
use nprt_scene::{CameraVolume, EnvMap};
use nprt_trace::{PixelFilter, RenderSettings, TraceScene};
use serde::{Deserialize, Serialize};

use crate::claim::Claim;
use crate::eval_options::EvalOptions;
use crate::method::{Family, MethodResult};
use crate::metrics::Metrics;
use crate::networks::{load_networks, run_networks, Net};
use crate::oracles::run_oracles;
use crate::path_tracing::{equal_time_spp, run_denoised, run_path_tracing, Traced};
use crate::sh_prt::run_sh_prt;
use crate::shown_view::ShownView;
use crate::temporal::{run_temporal, Temporal, TemporalSetup};
use crate::test_bench::TestBench;
use crate::timing::{time_table, Timing};

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Evaluation {
    pub data: PathBuf,
    pub scene: String,
    pub test_views: usize,
    pub resolution: [usize; 2],
    pub foreground_pixels: usize,
    /// Path tracing's sample count at the cost of the slowest design.
    pub equal_time_spp: u32,
    /// Samples per pixel of the references (the test views).
    #[serde(default)]
    pub reference_spp: u32,
    /// The references' own error: the first half of each reference's samples against the
    /// whole, which differs from it by noise of the reference's own size (None for a dataset
    /// whose test views were not rendered in halves).
    #[serde(default)]
    pub noise_floor: Option<Metrics>,
    pub methods: Vec<MethodResult>,
    pub timing_res: u32,
    pub timings: Vec<Timing>,
    /// f32 peak of `cpu_threads` threads, measured beside the timings.
    #[serde(default)]
    pub peak_gflops: f64,
    pub denoiser: String,
    pub cpu_threads: usize,
    /// Images of the shown views, per method (reference first), in the report's images folder.
    #[serde(skip)]
    pub shown: Vec<ShownView>,
    /// Indices of the shown views (kept in results.json, so that a report built later from it
    /// finds their images: [`crate::crop_image`]).
    #[serde(default)]
    pub shown_views: Vec<usize>,
    /// Every method along a camera path (None where it was not run; `temporal_note` says why).
    #[serde(default)]
    pub temporal: Option<Temporal>,
    #[serde(default)]
    pub temporal_note: String,
}

/// Runs the whole evaluation: the networks first (the slowest Neural PRT design sets the
/// equal-time sample count), then path tracing, denoised path tracing and SH PRT.
pub fn evaluate(o: &EvalOptions, engine: Engine) -> Result<Evaluation> {
    o.check(engine.tracer())?;
    let l = Loaded::new(o, engine)?;
    let (manifest, views, nets) = (&l.manifest, &l.views, &l.nets);
    let s = &manifest.settings;
    let ts = TraceScene::new(&l.scene);
    let oidn = Oidn::open();
    let denoiser = describe_denoiser(&oidn);
    let oidn_ok = oidn.as_ref().ok().copied();
    let tiers = equal_time_tiers(nets);
    let steps = views.len() * steps_per_view(o, nets, oidn_ok.is_some(), tiers.len());
    let mut bench = l.bench(&ts, o, o.shown_views, (steps, "evaluating", "steps"));

    // A stop requested (nprt_io::interrupt) ends it between stages, before any result; the
    // traced stages skip their remaining pixels meanwhile.
    let stop = nprt_io::interrupt::check;
    let mut results = run_networks(&mut bench, nets, oidn_ok)?;
    stop()?;
    let oracles = match o.oracles {
        true => run_oracles(&mut bench, nets, oidn_ok)?,
        false => Vec::new(),
    };
    let pt5 = run_path_tracing(&mut bench, "pt-5spp", 5, 0x5eed_0005);
    let equal_time = run_equal_time(&mut bench, &tiers, &pt5, &mut results);
    let equal_time_spp = equal_time.iter().map(|(n, _)| *n).max().unwrap_or(5);
    let mut baselines = Vec::new();
    if let Ok(oidn) = &oidn {
        for base in std::iter::once(&pt5).chain(equal_time.iter().map(|(_, t)| t)) {
            baselines.push(run_denoised(&mut bench, oidn, base)?);
        }
    }
    baselines.extend(run_sh_prt(&mut bench, o.sh_spp));
    bench.bar.finish_and_clear();
    let (traced, with) = ((&pt5, equal_time.as_slice()), (nets.as_slice(), engine));
    let what = (&ts, manifest);
    let (temporal, temporal_note) = temporal_run(o, what, &l.maps, with, traced, oidn_ok)?;
    stop()?;
    results.push(pt5.result);
    results.extend(equal_time.into_iter().map(|(_, t)| t.result));
    results.extend(baselines);
    results.extend(oracles);

    let direct = DirectSampling {
        spp: o.direct_spp,
        seed: o.seed,
        denoiser: oidn_ok,
    };
    let timings = time_table(&bench, o.timing_res, nets, direct)?;
    stop()?;
    check_finite(&results, views)?;
    Ok(Evaluation {
        data: o.data.clone(),
        scene: s.scene.clone(),
        test_views: views.len(),
        resolution: [views[0].width, views[0].height],
        foreground_pixels: views.iter().map(|v| v.foreground()).sum(),
        equal_time_spp,
        reference_spp: s.spp_of(&views[0].record),
        noise_floor: noise_floor(views),
        methods: results,
        timing_res: o.timing_res,
        timings,
        peak_gflops: nprt_net::cpu::measured_peak(rayon::current_num_threads()).gflops,
        denoiser,
        cpu_threads: rayon::current_num_threads(),
        shown_views: bench.shown.iter().map(|v| v.index).collect(),
        shown: bench.shown,
        temporal,
        temporal_note,
    })
}

/// Progress-bar steps per test view: each network (and each traced design denoised, where
/// OIDN is, and its oracles, where asked), path tracing at 5 spp and at each of `tiers` equal
/// times, SH PRT.
fn steps_per_view(o: &EvalOptions, nets: &[(Net, String)], oidn: bool, tiers: usize) -> usize {
    let traced = nets.iter().filter(|(n, _)| n.traces_direct()).count();
    nets.len() + traced * (usize::from(oidn) + usize::from(o.oracles)) + 2 + tiers
}

/// What an evaluation reads: the dataset's manifest, its scene, the test views evaluated with
/// their maps, and the networks (refused when trained on another scene).
struct Loaded {
    manifest: Manifest,
    scene: nprt_scene::Scene,
    views: Vec<ImageView>,
    maps: BTreeMap<usize, EnvMap>,
    nets: Vec<(Net, String)>,
}

impl Loaded {
    fn new(o: &EvalOptions, engine: Engine) -> Result<Loaded> {
        let (manifest, dataset_hash) = load_manifest_hashed(&o.data)?;
        let s = &manifest.settings;
        let scene = load_checked_scene(
            &s.scene,
            &s.scene_hash,
            &format!("dataset '{}' was rendered from", o.data.display()),
        )?;
        let views = test_views(o, &manifest)?;
        let maps = views_maps(&manifest, &views)?;
        let nets = load_networks(o, engine, &dataset_hash, &s.scene_hash)?;
        Ok(Loaded {
            manifest,
            scene,
            views,
            maps,
            nets,
        })
    }

    /// The test bench of these views and maps on `ts` (this scene's), its first `shown` views
    /// kept for the report, its progress `steps` long, named `what`, counted in `unit`.
    fn bench<'a>(
        &'a self,
        ts: &'a TraceScene<'a>,
        o: &EvalOptions,
        shown: usize,
        (steps, what, unit): (usize, &str, &str),
    ) -> TestBench<'a> {
        let shown = &self.views[..shown.min(self.views.len())];
        TestBench {
            views: &self.views,
            maps: &self.maps,
            ts,
            settings: &self.manifest.settings,
            seed: o.seed,
            direct_spp: o.direct_spp,
            shown: shown.iter().map(ShownView::of).collect(),
            bar: nprt_io::progress_bar(o.progress, steps as u64, what, unit),
        }
    }
}

/// The networks `o` names on the test views alone, without baselines, timings or the camera
/// path: what the paper's Table 2 (its ablation) compares.
pub fn score_networks(o: &EvalOptions, engine: Engine) -> Result<Vec<MethodResult>> {
    let l = Loaded::new(o, engine)?;
    let (views, nets) = (&l.views, &l.nets);
    let ts = TraceScene::new(&l.scene);
    let mut bench = l.bench(&ts, o, 0, (views.len() * nets.len(), "scoring", "views"));
    let results = run_networks(&mut bench, nets, None)?;
    bench.bar.finish_and_clear();
    check_finite(&results, views)?;
    Ok(results)
}

/// The temporal evaluation (`temporal::run_temporal`) at the options' frames and size, through
/// the camera volume the dataset's views were placed in (its manifest records it), the
/// lighting changing from the first held-out map to the second, with path tracing at the
/// largest equal-time sample count (5 spp without one); or why it was not run.
fn temporal_run(
    o: &EvalOptions,
    (ts, manifest): (&TraceScene, &Manifest),
    maps: &BTreeMap<usize, EnvMap>,
    (nets, engine): (&[(Net, String)], Engine),
    (pt5, equal_time): (&Traced, &[(u32, Traced)]),
    oidn: Option<&'static Oidn>,
) -> Result<(Option<Temporal>, String)> {
    let (spp, pt) = equal_time
        .iter()
        .max_by_key(|(n, _)| *n)
        .map_or((5, pt5), |(n, t)| (*n, t));
    let path_tracing = (pt.result.name.as_str(), spp);
    let settings = &manifest.settings;
    if o.temporal_frames == 0 {
        return Ok((None, "not run (--temporal-frames 0)".into()));
    }
    let volume = CameraVolume::from(&settings.camera_volume);
    let mut held_out = maps.values();
    let first = held_out.next().expect("a map per test view");
    let tracer = |spp, seed| RenderSettings {
        spp,
        max_depth: settings.max_depth,
        rr_depth: settings.rr_depth,
        seed,
        filter: PixelFilter::Centre,
        progress: false,
    };
    let setup = TemporalSetup {
        ts,
        volume: &volume,
        maps: [first, held_out.next().unwrap_or(first)],
        frames: o.temporal_frames,
        resolution: [o.temporal_res; 2],
        reference_spp: settings.test_spp.unwrap_or(settings.spp),
        tracer: &tracer,
        seed: o.seed,
        direct_spp: o.direct_spp,
        bounds: manifest.bounds,
        nrc_warmup: o.nrc_warmup,
        engine,
    };
    let rows = nets.len()
        + nets.iter().filter(|(n, _)| n.traces_direct()).count() * usize::from(oidn.is_some());
    let steps = (o.temporal_frames * (rows + 2)) as u64;
    let bar = nprt_io::progress_bar(o.progress, steps, "along a camera path", "frames");
    let t = run_temporal(&setup, nets, path_tracing, oidn, &|| bar.inc(1))?;
    bar.finish_and_clear();
    Ok((Some(t), String::new()))
}

/// The maps of the views evaluated, by index: only those, since a dataset with a fresh map per
/// training view has thousands of others.
fn views_maps(manifest: &Manifest, views: &[ImageView]) -> Result<BTreeMap<usize, EnvMap>> {
    views
        .iter()
        .map(|v| v.record.map)
        .collect::<BTreeSet<_>>()
        .into_iter()
        .map(|m| Ok((m, open_recorded_map(manifest, m)?)))
        .collect()
}

/// The denoiser for the report: OIDN's settings, or why it is unavailable.
fn describe_denoiser(oidn: &Result<&'static Oidn>) -> String {
    match oidn {
        Ok(_) => "Intel Open Image Denoise 1.4.3 (RT filter, HDR, albedo and normal auxiliaries)"
            .to_string(),
        Err(e) => format!("unavailable: {e:#}"),
    }
}

/// Stops at a metric that is not a finite number (it would be `null` in results.json and
/// silently drop out of every mean), naming the method and test view; the light level and tint,
/// undefined where a test view's reference holds no light in a channel, likewise.
fn check_finite(results: &[MethodResult], views: &[ImageView]) -> Result<()> {
    for r in results {
        if !(r.level.iter().all(|x| x.is_finite()) && r.tint_error.is_finite()) {
            let dark = views.iter().find(|v| {
                let l = crate::error_analysis::light(&v.radiance, &v.gbuffer.mask);
                l.min_element() <= 0.0
            });
            let why = match dark {
                Some(v) => format!(
                    "test view {} ('{}') holds no light in a channel of its reference (its map lights nothing there)",
                    v.record.index, v.record.file
                ),
                None => "the test views' light sums to nothing".into(),
            };
            bail!(
                "{}: its light level {:?} and tint error {} against the references are not numbers, so no report is written: {why}",
                r.name,
                r.level,
                r.tint_error
            );
        }
        for (m, v) in r.per_view.iter().zip(views) {
            let values = m.values();
            if let Some(k) = values.iter().position(|x| !x.is_finite()) {
                bail!(
                    "{}: {} on test view {} ('{}') is {}, so no report is written",
                    r.name,
                    Metrics::NAMES[k],
                    v.record.index,
                    v.record.file,
                    values[k]
                );
            }
        }
    }
    Ok(())
}

/// The test views evaluated, in index order, the first `max_views` of them.
fn test_views(o: &EvalOptions, manifest: &Manifest) -> Result<Vec<ImageView>> {
    let mut views = load_views(&o.data, manifest, "test")?;
    views.sort_by_key(|v| v.record.index);
    if let Some(n) = o.max_views {
        views.truncate(n);
    }
    if views.is_empty() {
        bail!("dataset '{}' has no test views", o.data.display());
    }
    Ok(views)
}

/// Path tracing at each tier's equal time (one row per distinct sample count), filing every
/// design's row under its tier's peer; returns the rows with their sample counts.
fn run_equal_time(
    bench: &mut TestBench,
    tiers: &[Tier],
    pt5: &Traced,
    results: &mut [MethodResult],
) -> Vec<(u32, Traced)> {
    let mut equal_time: Vec<(u32, Traced)> = Vec::new();
    for tier in tiers {
        let ms = tier.slowest_ms(results);
        let spp = equal_time_spp(&pt5.result, ms);
        let name = format!("pt-equal-time ({spp} spp)");
        // A design's row and its denoised row (traced light denoised), each held to path
        // tracing treated alike.
        for r in results.iter_mut() {
            let plain = r.name.strip_suffix(" + OIDN").unwrap_or(&r.name);
            if tier.rows.iter().any(|t| t == plain) {
                r.equal_time = Some(match r.family {
                    Family::Denoised => format!("{name} + OIDN"),
                    _ => name.clone(),
                });
            }
        }
        // Two tiers of equal cost share one row.
        if equal_time.iter().any(|(n, _)| *n == spp) {
            continue;
        }
        let mut pt = run_path_tracing(bench, &name, spp, 0x5eed_e9a1);
        pt.result.note = format!("{spp} spp: the time of {} ({ms:.0} ms per view)", tier.what);
        equal_time.push((spp, pt));
    }
    equal_time
}

/// The references' own error: each test view's first half of samples against the whole.
fn noise_floor(views: &[ImageView]) -> Option<Metrics> {
    views
        .iter()
        .map(|v| {
            let half = v.half.as_ref()?;
            Some(Metrics::compute(
                half,
                &v.radiance,
                &v.gbuffer.mask,
                v.width,
            ))
        })
        .collect::<Option<Vec<_>>>()
        .map(|per_view| Metrics::mean(&per_view))
}

impl Evaluation {
    pub fn method(&self, name: &str) -> Option<&MethodResult> {
        self.methods.iter().find(|m| m.name == name)
    }

    /// The claims the paper makes and the demo must show, each judged on the per-view
    /// differences (a claim the test views cannot decide is reported as such).
    pub fn checks(&self) -> Vec<Claim> {
        let (l1, rmse, log_l1) = (Metrics::L1, Metrics::RMSE, Metrics::LOG_L1);
        let mut out = Vec::new();
        if let (Some(d), Some(b)) = (self.method("nprt-dsep"), self.method("nprt-baseline")) {
            out.push(Claim::beats(d, b, rmse));
        }
        // The paper's order of its four designs: D/S ≤ albedo ≤ PRT < baseline in log-L1 and
        // RMSE, claimed pair by pair.
        let order: Vec<&MethodResult> = ["nprt-dsep", "nprt-albedo", "nprt-prt", "nprt-baseline"]
            .iter()
            .filter_map(|n| self.method(n))
            .collect();
        for metric in [log_l1, rmse] {
            for pair in order.windows(2) {
                out.push(Claim::beats(pair[0], pair[1], metric));
            }
        }
        let sh9 = self.method("sh-prt-9");
        // Each design against SH PRT 9 and path tracing of its own cost; a design whose traced
        // light is denoised, against path tracing denoised alike.
        for m in self.methods.iter().filter(|m| {
            m.family == Family::NeuralPrt
                || (m.family == Family::Denoised && m.name.starts_with("nprt-"))
        }) {
            let sh = sh9.filter(|_| m.family == Family::NeuralPrt);
            let pt = m.equal_time.as_deref().and_then(|n| self.method(n));
            for other in [sh, pt].into_iter().flatten() {
                out.push(Claim::beats(m, other, l1));
            }
        }
        out.extend(self.temporal_checks());
        out
    }

    /// The paper's argument from temporal artefacts: D/S flickers less than Deep Shading, than
    /// denoised path tracing of its cost and than the radiance caches trained online, judged
    /// over the path's frame pairs; and it beats the caches in the frames after the lighting
    /// changes, which they lag.
    fn temporal_checks(&self) -> Vec<Claim> {
        let Some(t) = &self.temporal else {
            return Vec::new();
        };
        let Some(ds) = t.method("nprt-dsep") else {
            return Vec::new();
        };
        let denoised = t
            .methods
            .iter()
            .find(|m| m.name.starts_with("pt-") && m.name.ends_with(" + OIDN"));
        let caches = ["nrc", "nrc-cache"].map(|n| t.method(n));
        let mut out: Vec<Claim> = [t.method("deep-shading"), denoised]
            .into_iter()
            .chain(caches)
            .flatten()
            .map(|other| Claim::steadier(ds, other))
            .collect();
        // A cache trained online lags a change of light; D/S was trained for every light.
        let after = caches.into_iter().flatten();
        out.extend(after.map(|c| Claim::beats_from_frame(ds, c, t.change_at)));
        out
    }
}

/// Designs of one cost tier, which are compared with path tracing of their slowest one's cost.
struct Tier {
    /// The tier's slowest design, in words.
    what: &'static str,
    /// Names of the tier's rows.
    rows: Vec<String>,
}

impl Tier {
    /// Time per view of the tier's slowest design.
    fn slowest_ms(&self, results: &[MethodResult]) -> f64 {
        results
            .iter()
            .filter(|r| self.rows.contains(&r.name))
            .map(|r| r.ms_per_view)
            .fold(0.0, f64::max)
    }
}

/// Equal time is set per tier of Neural PRT designs: those that learn all their light, and
/// those that trace their direct light, which costs them the tracing too. Each design is held
/// to path tracing of its tier's slowest design, not to one that costs the traced designs'
/// time. With no design, the slowest network given (Deep Shading is a baseline) sets it.
fn equal_time_tiers(nets: &[(Net, String)]) -> Vec<Tier> {
    let tiers: Vec<Tier> = [
        (false, "the slowest design that learns all its light"),
        (true, "the slowest design that traces its direct light"),
    ]
    .into_iter()
    .map(|(traced, what)| Tier {
        what,
        rows: nets
            .iter()
            .filter(|(n, _)| n.family() == Family::NeuralPrt && n.traces_direct() == traced)
            .map(|(_, name)| name.clone())
            .collect(),
    })
    .filter(|t| !t.rows.is_empty())
    .collect();
    if !tiers.is_empty() {
        return tiers;
    }
    vec![Tier {
        what: "the slowest network",
        rows: nets.iter().map(|(_, name)| name.clone()).collect(),
    }]
}
