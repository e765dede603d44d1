//! The paper's evaluation: every trained design and every baseline on the dataset's test views
//! (held-out lighting), their errors, the error analysis against directness and specularity,
//! and timings at a fixed resolution (the paper's Tables 3 and 4).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Result};
use glam::Vec3;
use nprt_data::dataset::{load_checked_scene, load_manifest_hashed, Manifest};
use nprt_net::data::open_recorded_maps;
use nprt_net::Device;
use nprt_render::{LightCode, Relighter};
use nprt_scene::{luminance, Camera, EnvMap};
use nprt_trace::{render, render_gbuffer, GBuffer, PixelFilter, RenderSettings, TraceScene};
use serde::{Deserialize, Serialize};

use crate::deep_shading::DeepShadingModel;
use crate::metrics::{correlation, Metrics};
use crate::oidn::Oidn;
use crate::sh::ShTransport;
use nprt_data::views::{load_views, ImageView};

#[derive(Clone, Debug)]
pub struct EvalOptions {
    pub data: PathBuf,
    pub models: Vec<PathBuf>,
    pub deep_shading: Option<PathBuf>,
    /// Paths per pixel of the SH transport precomputation.
    pub sh_spp: u32,
    /// Side of the square frames of the timing table (the paper: 512).
    pub timing_res: u32,
    /// Evaluate only the first N test views.
    pub max_views: Option<usize>,
    /// Test views shown as images in the report.
    pub shown_views: usize,
    pub seed: u64,
    pub progress: bool,
}

/// What kind of method a row is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    Neural,
    Baseline,
}

/// Bins of the error analysis (directness and specularity in [0, 1]).
pub const BINS: usize = 10;

/// One method's results over the test views.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MethodResult {
    pub name: String,
    pub kind: Kind,
    /// Transport parameters (networks only).
    pub params: Option<usize>,
    pub mean: Metrics,
    pub per_view: Vec<Metrics>,
    /// Mean milliseconds per test view at the test resolution (what the method costs at run
    /// time: G-buffer + encoder + network for networks, tracing for path tracing, projection +
    /// dot products for SH).
    pub ms_per_view: f64,
    /// One-off precomputation per view (SH transport), milliseconds.
    pub precompute_ms: Option<f64>,
    /// Pearson correlation over foreground pixels of the per-pixel L1 error with the share of
    /// direct light, and with specularity.
    pub corr_directness: f64,
    pub corr_specularity: f64,
    /// Mean per-pixel L1 error in each directness / specularity bin.
    pub error_by_directness: Vec<f64>,
    pub error_by_specularity: Vec<f64>,
    pub note: String,
    /// Training curve, for networks.
    pub loss_png: Option<PathBuf>,
}

/// Rows of the timing table.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Timing {
    pub what: String,
    pub ms: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Evaluation {
    pub data: PathBuf,
    pub scene: String,
    pub test_views: usize,
    pub resolution: [usize; 2],
    pub foreground_pixels: usize,
    pub equal_time_spp: u32,
    pub methods: Vec<MethodResult>,
    pub timing_res: u32,
    pub timings: Vec<Timing>,
    pub denoiser: String,
    pub cpu_threads: usize,
    /// Images of the shown views, per method (reference first), in the report's images folder.
    #[serde(skip)]
    pub shown: Vec<ShownView>,
}

/// A test view's images for the report.
#[derive(Clone, Debug)]
pub struct ShownView {
    pub index: usize,
    pub width: usize,
    pub height: usize,
    pub mask: Vec<f32>,
    pub reference: Vec<Vec3>,
    /// (method name, radiance).
    pub methods: Vec<(String, Vec<Vec3>)>,
}

/// Accumulates one method's per-view metrics and per-pixel error statistics.
struct Accumulator {
    result: MethodResult,
    err: Vec<f64>,
    direct: Vec<f64>,
    spec: Vec<f64>,
    ms: Vec<f64>,
}

impl Accumulator {
    fn new(name: &str, kind: Kind, params: Option<usize>) -> Self {
        Accumulator {
            result: MethodResult {
                name: name.into(),
                kind,
                params,
                mean: Metrics::default(),
                per_view: vec![],
                ms_per_view: 0.0,
                precompute_ms: None,
                corr_directness: 0.0,
                corr_specularity: 0.0,
                error_by_directness: vec![],
                error_by_specularity: vec![],
                note: String::new(),
                loss_png: None,
            },
            err: vec![],
            direct: vec![],
            spec: vec![],
            ms: vec![],
        }
    }

    fn add(&mut self, view: &ImageView, pred: &[Vec3], ms: f64) {
        let g = &view.gbuffer;
        self.result
            .per_view
            .push(Metrics::compute(pred, &view.radiance, &g.mask, view.width));
        self.ms.push(ms);
        for i in (0..g.mask.len()).filter(|&i| g.mask[i] > 0.5) {
            let r = view.radiance[i];
            self.err
                .push(((pred[i] - r).abs().element_sum() / 3.0) as f64);
            self.direct
                .push((luminance(view.direct[i]) / luminance(r).max(1e-6)).clamp(0.0, 1.0) as f64);
            let (kd, ks) = (g.kd[i].element_sum(), g.ks[i].element_sum());
            self.spec.push((ks / (kd + ks).max(1e-6)) as f64);
        }
    }

    fn finish(mut self) -> MethodResult {
        let r = &mut self.result;
        r.mean = Metrics::mean(&r.per_view);
        r.ms_per_view = self.ms.iter().sum::<f64>() / self.ms.len().max(1) as f64;
        r.corr_directness = correlation(&self.err, &self.direct);
        r.corr_specularity = correlation(&self.err, &self.spec);
        r.error_by_directness = binned(&self.direct, &self.err);
        r.error_by_specularity = binned(&self.spec, &self.err);
        self.result
    }
}

/// Mean of `y` in `BINS` equal bins of `x` ∈ [0, 1] (NaN where a bin is empty).
fn binned(x: &[f64], y: &[f64]) -> Vec<f64> {
    let mut sum = vec![0.0; BINS];
    let mut n = vec![0usize; BINS];
    for (a, b) in x.iter().zip(y) {
        let k = ((a * BINS as f64) as usize).min(BINS - 1);
        sum[k] += b;
        n[k] += 1;
    }
    sum.iter()
        .zip(&n)
        .map(|(s, &c)| if c > 0 { s / c as f64 } else { f64::NAN })
        .collect()
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// A network under evaluation.
enum Net {
    Nprt(Box<Relighter>, PathBuf),
    DeepShading(Box<DeepShadingModel>, PathBuf),
}

impl Net {
    fn kind_name(&self) -> String {
        match self {
            Net::Nprt(r, _) => format!("nprt-{}", r.file.config.design.name()),
            Net::DeepShading(..) => "deep-shading".into(),
        }
    }

    fn dir(&self) -> &Path {
        match self {
            Net::Nprt(_, d) | Net::DeepShading(_, d) => d,
        }
    }

    /// Radiance of a G-buffer under a map, and (encoder, network) milliseconds.
    fn shade(
        &self,
        g: &GBuffer,
        w: usize,
        h: usize,
        map: &EnvMap,
        rotation: f32,
    ) -> (Vec<Vec3>, f64, f64) {
        match self {
            Net::Nprt(r, _) => {
                let t = Instant::now();
                let code: LightCode = r.light_code(map, rotation);
                let enc = ms(t);
                let t = Instant::now();
                let rgb = r.shade(g, &code);
                (rgb, enc, ms(t))
            }
            Net::DeepShading(d, _) => {
                let t = Instant::now();
                let rgb = d.shade(g, w, h, map, rotation);
                (rgb, 0.0, ms(t))
            }
        }
    }
}

fn check_model(
    dir: &Path,
    dataset_hash: &str,
    scene_hash: &str,
    model_scene: &str,
    model_data: &str,
) -> Result<()> {
    if model_scene != scene_hash {
        bail!(
            "model '{}' was trained on another scene than the dataset's",
            dir.display()
        );
    }
    if model_data != dataset_hash {
        eprintln!(
            "note: model '{}' was trained on another dataset of the same scene; its test views may not be held out",
            dir.display()
        );
    }
    Ok(())
}

/// Runs the whole evaluation.
pub fn evaluate(o: &EvalOptions, device: &Device) -> Result<Evaluation> {
    let (manifest, dataset_hash): (Manifest, _) = load_manifest_hashed(&o.data)?;
    let s = &manifest.settings;
    let scene = load_checked_scene(
        &s.scene,
        &s.scene_hash,
        &format!("dataset '{}' was rendered from", o.data.display()),
    )?;
    let maps = open_recorded_maps(&manifest)?;
    let mut views = load_views(&o.data, &manifest, "test")?;
    views.sort_by_key(|v| v.record.index);
    if let Some(n) = o.max_views {
        views.truncate(n);
    }
    if views.is_empty() {
        bail!("dataset '{}' has no test views", o.data.display());
    }
    let mut nets = Vec::new();
    for dir in &o.models {
        let r = Relighter::load(dir, device)?;
        check_model(
            dir,
            &dataset_hash,
            &s.scene_hash,
            &r.file.scene_hash,
            &r.file.dataset_hash,
        )?;
        nets.push(Net::Nprt(Box::new(r), dir.clone()));
    }
    if let Some(dir) = &o.deep_shading {
        let d = DeepShadingModel::load(dir, device)?;
        check_model(
            dir,
            &dataset_hash,
            &s.scene_hash,
            &d.file.scene_hash,
            &d.file.dataset_hash,
        )?;
        nets.push(Net::DeepShading(Box::new(d), dir.clone()));
    }
    if nets.is_empty() {
        bail!("give at least one model to evaluate (--model)");
    }
    // Two models of one design are told apart by their folders.
    let names: Vec<String> = nets
        .iter()
        .map(|n| {
            let same = nets
                .iter()
                .filter(|m| m.kind_name() == n.kind_name())
                .count();
            match same {
                1 => n.kind_name(),
                _ => format!("{} ({})", n.kind_name(), n.dir().display()),
            }
        })
        .collect();
    let ts = TraceScene::new(&scene);
    let pt_settings = |spp: u32, seed: u64| RenderSettings {
        spp,
        max_depth: s.max_depth,
        rr_depth: s.rr_depth,
        seed,
        filter: PixelFilter::Centre,
        progress: false,
    };
    let oidn = Oidn::open();
    let denoiser = match &oidn {
        Ok(_) => "Intel Open Image Denoise 1.4.3 (RT filter, HDR, albedo and normal auxiliaries)"
            .to_string(),
        Err(e) => format!("unavailable: {e:#}"),
    };
    let shown_n = o.shown_views.min(views.len());
    let mut shown: Vec<ShownView> = views[..shown_n]
        .iter()
        .map(|v| ShownView {
            index: v.record.index as usize,
            width: v.width,
            height: v.height,
            mask: v.gbuffer.mask.clone(),
            reference: v.radiance.clone(),
            methods: vec![],
        })
        .collect();
    let total_steps = (views.len() * (nets.len() + 3)) as u64;
    let bar = nprt_io::progress_bar(o.progress, total_steps, "evaluating", "steps");

    // Networks first: the slowest one sets the equal-time sample count.
    let mut results = Vec::new();
    for (net, name) in nets.iter().zip(&names) {
        let (params, loss_png) = match net {
            Net::Nprt(r, dir) => (Some(r.file.transport_params), dir.join("loss.png")),
            Net::DeepShading(d, dir) => (Some(d.file.unet_params), dir.join("loss.png")),
        };
        let mut acc = Accumulator::new(name, Kind::Neural, params);
        acc.result.loss_png = loss_png.is_file().then_some(loss_png);
        for (k, v) in views.iter().enumerate() {
            bar.set_message(name.clone());
            let t = Instant::now();
            let g = render_gbuffer(&ts, &v.camera);
            let g_ms = ms(t);
            let (rgb, enc, netms) = net.shade(
                &g,
                v.width,
                v.height,
                &maps[v.record.map],
                v.record.rotation_deg,
            );
            acc.add(v, &rgb, g_ms + enc + netms);
            if k < shown_n {
                shown[k].methods.push((name.clone(), rgb));
            }
            bar.inc(1);
        }
        results.push(acc.finish());
    }
    // Equal time is set by the Neural PRT designs (Deep Shading is a baseline); with none, by
    // whatever network was given.
    let designs: Vec<&MethodResult> = results
        .iter()
        .filter(|r| r.name.starts_with("nprt-"))
        .collect();
    let pool = if designs.is_empty() {
        results.iter().collect()
    } else {
        designs
    };
    let slowest_ms = pool.iter().map(|r| r.ms_per_view).fold(0.0, f64::max);

    // Path tracing of every view at `spp`, timed per view; `salt` keeps the seeds apart.
    let trace_all = |name: &str, spp: u32, salt: u64| {
        let mut acc = Accumulator::new(name, Kind::Baseline, None);
        let mut frames = Vec::new();
        for v in &views {
            bar.set_message(format!("path tracing {spp} spp"));
            let map = maps[v.record.map].rotated_y(v.record.rotation_deg);
            let t = Instant::now();
            let f = render(
                &ts,
                &v.camera,
                &map,
                &pt_settings(spp, v.record.seed ^ o.seed ^ salt),
            );
            acc.add(v, &f.radiance, ms(t));
            frames.push(f.radiance);
            bar.inc(1);
        }
        (acc.finish(), frames)
    };
    // 5 spp first: its cost per sample sets the equal-time count.
    let (pt5, pt5_frames) = trace_all("pt-5spp", 5, 0x5eed_0005);
    let equal_time_spp = ((slowest_ms / (pt5.ms_per_view / 5.0)).round() as u32).max(1);
    let (mut pteq, pteq_frames) = trace_all(
        &format!("pt-equal-time ({equal_time_spp} spp)"),
        equal_time_spp,
        0x5eed_e9a1,
    );
    pteq.note = format!(
        "{equal_time_spp} spp: the time of the slowest design ({slowest_ms:.0} ms per view)"
    );
    for (k, (a, b)) in pt5_frames
        .iter()
        .zip(&pteq_frames)
        .take(shown_n)
        .enumerate()
    {
        shown[k].methods.push((pt5.name.clone(), a.clone()));
        shown[k].methods.push((pteq.name.clone(), b.clone()));
    }
    let mut baselines = vec![pt5, pteq];

    // The same, denoised.
    if let Ok(oidn) = oidn {
        for (frames, base) in [
            (&pt5_frames, baselines[0].name.clone()),
            (&pteq_frames, baselines[1].name.clone()),
        ] {
            let mut acc = Accumulator::new(&format!("{base} + OIDN"), Kind::Baseline, None);
            let base_ms = baselines
                .iter()
                .find(|b| b.name == base)
                .map_or(0.0, |b| b.ms_per_view);
            for (k, (v, f)) in views.iter().zip(frames.iter()).enumerate() {
                let albedo: Vec<Vec3> = (0..f.len())
                    .map(|i| (v.gbuffer.kd[i] + v.gbuffer.ks[i]).min(Vec3::ONE))
                    .collect();
                let t = Instant::now();
                let d = oidn.denoise(f, &albedo, &v.gbuffer.normal, v.width, v.height)?;
                acc.add(v, &d, base_ms + ms(t));
                if k < shown_n {
                    shown[k].methods.push((acc.result.name.clone(), d));
                }
            }
            baselines.push(acc.finish());
        }
    }

    // SH PRT with 25 and 9 coefficients per channel: one transport precomputation per view.
    let mut sh = [
        Accumulator::new("sh-prt-9", Kind::Baseline, None),
        Accumulator::new("sh-prt-25", Kind::Baseline, None),
    ];
    let mut pre_ms = 0.0;
    for (k, v) in views.iter().enumerate() {
        bar.set_message(format!("SH transport, {} paths per pixel", o.sh_spp));
        let t = Instant::now();
        let t25 = ShTransport::precompute(
            &ts,
            &v.camera,
            5,
            &pt_settings(o.sh_spp, v.record.seed ^ o.seed ^ 0x5eed_0525),
        );
        pre_ms += ms(t);
        let map = maps[v.record.map].rotated_y(v.record.rotation_deg);
        for (acc, transport) in sh.iter_mut().zip([t25.truncated(3), t25]) {
            let t = Instant::now();
            let rgb = transport.shade(&map);
            acc.add(v, &rgb, ms(t));
            if k < shown_n {
                shown[k].methods.push((acc.result.name.clone(), rgb));
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    for acc in sh {
        let mut r = acc.finish();
        r.precompute_ms = Some(pre_ms / views.len() as f64);
        r.note = format!(
            "transport path-traced at {} paths per pixel per view (fixed view)",
            o.sh_spp
        );
        baselines.push(r);
    }
    results.extend(baselines);

    let timings = time_table(
        o,
        &ts,
        &views[0].camera,
        &maps[views[0].record.map],
        &nets,
        &names,
        &pt_settings(5, o.seed),
    )?;
    let fg = views.iter().map(|v| v.foreground()).sum();
    Ok(Evaluation {
        data: o.data.clone(),
        scene: s.scene.clone(),
        test_views: views.len(),
        resolution: [views[0].width, views[0].height],
        foreground_pixels: fg,
        equal_time_spp,
        methods: results,
        timing_res: o.timing_res,
        timings,
        denoiser,
        cpu_threads: rayon::current_num_threads(),
        shown,
    })
}

/// The paper's Tables 3 and 4 on this machine: per-stage times of one frame at
/// `timing_res`², the median of three runs each.
fn time_table(
    o: &EvalOptions,
    ts: &TraceScene,
    camera: &Camera,
    map: &EnvMap,
    nets: &[Net],
    names: &[String],
    pt: &RenderSettings,
) -> Result<Vec<Timing>> {
    let camera = camera.with_resolution(o.timing_res, o.timing_res);
    let n = o.timing_res as usize;
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut rows = Vec::new();
    let mut g = GBuffer::default();
    let gb = median(
        (0..3)
            .map(|_| {
                let t = Instant::now();
                g = render_gbuffer(ts, &camera);
                ms(t)
            })
            .collect(),
    );
    rows.push(Timing {
        what: "G-buffer (primary rays)".into(),
        ms: gb,
    });
    for (net, name) in nets.iter().zip(names) {
        let runs: Vec<(f64, f64)> = (0..3)
            .map(|_| {
                let (_, e, m) = net.shade(&g, n, n, map, 0.0);
                (e, m)
            })
            .collect();
        if let Net::Nprt(..) = net {
            rows.push(Timing {
                what: format!("{name}: encoder"),
                ms: median(runs.iter().map(|r| r.0).collect()),
            });
        }
        rows.push(Timing {
            what: format!("{name}: network"),
            ms: median(runs.iter().map(|r| r.1).collect()),
        });
    }
    let pt_ms = median(
        (0..3)
            .map(|_| {
                let t = Instant::now();
                render(ts, &camera, map, pt);
                ms(t)
            })
            .collect(),
    );
    rows.push(Timing {
        what: "path tracing, 5 spp".into(),
        ms: pt_ms,
    });
    if rows.iter().any(|r| !r.ms.is_finite()) {
        bail!("a timing was not finite");
    }
    Ok(rows)
}

impl Evaluation {
    pub fn method(&self, name: &str) -> Option<&MethodResult> {
        self.methods.iter().find(|m| m.name == name)
    }

    /// The claims the paper makes and the demo must show, each with whether it holds here.
    pub fn checks(&self) -> Vec<(String, bool)> {
        let mut out = Vec::new();
        if let (Some(d), Some(b)) = (self.method("nprt-dsep"), self.method("nprt-baseline")) {
            out.push((
                format!(
                    "D/S beats the baseline design in RMSE ({:.4} < {:.4})",
                    d.mean.rmse, b.mean.rmse
                ),
                d.mean.rmse < b.mean.rmse,
            ));
        }
        let sh9 = self.method("sh-prt-9");
        let pteq = self
            .methods
            .iter()
            .find(|m| m.name.starts_with("pt-equal-time") && !m.name.ends_with("OIDN"));
        for m in self.methods.iter().filter(|m| m.name.starts_with("nprt-")) {
            for other in [sh9, pteq].into_iter().flatten() {
                out.push((
                    format!(
                        "{} beats {} in L1 ({:.4} < {:.4})",
                        m.name, other.name, m.mean.l1, other.mean.l1
                    ),
                    m.mean.l1 < other.mean.l1,
                ));
            }
        }
        out
    }
}
