//! `nprt demo`: the whole pipeline on the built-in scene and lighting, sized for a laptop CPU.
//! Every stage runs with its library's defaults except the sizes below.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use nprt_data::GenerateOptions;
use nprt_eval::claim::Verdict;
use nprt_eval::{EvalOptions, Evaluation};
use nprt_net::deep_shading::DeepShadingOptions;
use nprt_net::{Design, DirectLight, Engine, ModelConfig, RunLength, TrainOptions};
use nprt_render::oidn::Oidn;
use nprt_render::RenderOptions;

use crate::eval::EvalJob;
use crate::flags::DeviceArg;
use crate::train::TrainJob;
use crate::train_deep_shading::DeepShadingJob;

#[derive(clap::Args)]
pub struct DemoArgs {
    /// Output folder (dataset, models, report, relit frames). Re-running resumes what is done.
    #[arg(long, default_value = "nprt-demo")]
    out: PathBuf,
    /// Tiny sizes (under a minute on 2 cores): checks the pipeline, not the method.
    #[arg(long)]
    quick: bool,
    #[command(flatten)]
    device: DeviceArg,
}

/// The demo's sizes.
struct Plan {
    train_views: u64,
    test_views: u64,
    train_res: u32,
    test_res: u32,
    spp: u32,
    test_spp: u32,
    /// Each design's training (the measured recipe, unless it says otherwise).
    training: RunLength,
    deep_shading: RunLength,
    sh_spp: u32,
    timing_res: u32,
    /// The temporal evaluation's frames and their side.
    temporal: (usize, u32),
    frames: usize,
    frame_res: u32,
}

/// 800 lightings at 32² rather than 200 at 64² (the same pixels and tracing time): held-out
/// lighting is what the networks fail at, and more lightings teach the encoder more
/// (docs/evaluation.md#what-the-demo-shows). For the same reason 48 test lightings at 64²
/// rather than 16 at 96²: the paper's designs differ by less than 16 lightings resolve.
const FULL: Plan = Plan {
    train_views: 800,
    test_views: 48,
    train_res: 32,
    test_res: 64,
    spp: 64,
    test_spp: 1024,
    training: RunLength::minutes(2.0),
    deep_shading: RunLength::minutes(2.0),
    sh_spp: 256,
    timing_res: 512,
    temporal: (12, 64),
    frames: 48,
    frame_res: 128,
};

const QUICK: Plan = Plan {
    train_views: 24,
    test_views: 4,
    train_res: 32,
    test_res: 32,
    spp: 16,
    test_spp: 32,
    training: RunLength::epochs(2),
    deep_shading: RunLength::epochs(2),
    sh_spp: 16,
    timing_res: 64,
    temporal: (6, 32),
    frames: 4,
    frame_res: 48,
};

/// Announces each step with the time so far.
struct Steps(Instant);

impl Steps {
    fn begin(&self, what: &str) {
        println!(
            "\n== {what} ({:.0} s so far)",
            self.0.elapsed().as_secs_f64()
        );
    }
}

pub fn run(a: DemoArgs) -> Result<()> {
    let p = if a.quick { QUICK } else { FULL };
    let engine = a.device.engine()?;
    let steps = Steps(Instant::now());
    let data = a.out.join("dataset");
    steps
        .begin("1/5 generating the dataset: builtin:room under the built-in skies and indoor maps");
    crate::generate::run(&GenerateOptions {
        scene: "builtin:room".into(),
        envmaps: "builtin".into(),
        out: data.clone(),
        train_views: p.train_views,
        test_views: p.test_views,
        train_resolution: [p.train_res; 2],
        test_resolution: [p.test_res; 2],
        spp: p.spp,
        test_spp: p.test_spp,
        ..GenerateOptions::default()
    })?;
    let models = train_designs(&p, &data, &a.out, engine, &steps)?;
    steps.begin("3/5 training the Deep Shading baseline");
    let deep = a.out.join("models").join("deep-shading");
    let defaults = DeepShadingOptions::default();
    crate::train_deep_shading::run(&DeepShadingJob {
        data: data.clone(),
        opts: DeepShadingOptions {
            schedule: p.deep_shading.apply(defaults.schedule.clone()),
            ..defaults
        },
        out: deep.clone(),
        engine,
    })?;
    steps.begin("4/5 evaluating against the baselines");
    let report = a.out.join("report");
    let e = crate::eval::run(
        &EvalJob {
            opts: EvalOptions {
                data: data.clone(),
                models: models.clone(),
                deep_shading: Some(deep),
                sh_spp: p.sh_spp,
                timing_res: p.timing_res,
                temporal_frames: p.temporal.0,
                temporal_res: p.temporal.1,
                ..EvalOptions::default()
            },
            out: report.clone(),
        },
        engine,
    )?;
    steps.begin("5/5 relighting a camera path under held-out lighting");
    let frames = a.out.join("relit");
    relight(
        &p,
        &data,
        models.last().expect("five models"),
        &frames,
        engine,
    )?;
    println!(
        "\n== nprt demo done in {:.0} s",
        steps.0.elapsed().as_secs_f64()
    );
    println!("report: {}", report.join("report.html").display());
    println!("relit frames: {}", frames.display());
    print_headline(&e);
    Ok(())
}

/// The paper's four designs, then D/S with its direct light traced at run time (the paper's
/// suggested extension, docs/model.md); returns their model folders in that order.
fn train_designs(
    p: &Plan,
    data: &Path,
    out: &Path,
    engine: Engine,
    steps: &Steps,
) -> Result<Vec<PathBuf>> {
    let runs: Vec<ModelConfig> = Design::ALL
        .into_iter()
        .map(|d| ModelConfig::new(d, None))
        .chain([ModelConfig {
            direct: DirectLight::Traced,
            ..ModelConfig::new(Design::Dsep, None)
        }])
        .collect();
    let mut models = Vec::new();
    for (i, config) in runs.iter().enumerate() {
        steps.begin(&format!(
            "2/5 training design {} of {}: {}",
            i + 1,
            runs.len(),
            config.label()
        ));
        let job = TrainJob {
            data: data.to_path_buf(),
            config: config.clone(),
            opts: TrainOptions::default().with_run(config.design, p.training, None),
            out: out.join("models").join(config.label()),
        };
        crate::train::run(&job, engine)?;
        models.push(job.out);
    }
    Ok(models)
}

/// A camera path through the scene, relit by `model` under the dataset's held-out maps.
fn relight(p: &Plan, data: &Path, model: &Path, frames: &Path, engine: Engine) -> Result<()> {
    let manifest = nprt_data::dataset::load_manifest(data)?;
    let s = &manifest.settings;
    let held_out: Vec<&str> = s
        .test_maps
        .iter()
        .map(|&k| s.envmaps[k].spec.as_str())
        .collect();
    crate::render::run(
        &RenderOptions {
            model: model.to_path_buf(),
            out: frames.to_path_buf(),
            lighting: held_out.join(","),
            frames: p.frames,
            resolution: [p.frame_res; 2],
            // The traced light denoised where OIDN is installed: the cleaner frames.
            denoise_direct: Oidn::open().is_ok(),
            ..RenderOptions::default()
        },
        engine,
    )
}

/// The figures the demo exists for: each design against path tracing of its own cost, and
/// the paper's claims as the report judges them.
fn print_headline(e: &Evaluation) {
    let l1 = |name: &str| e.method(name).map(|m| m.mean.l1);
    if let (Some(d), Some(b)) = (e.method("nprt-dsep"), e.method("nprt-baseline")) {
        println!(
            "headline: RMSE D/S {:.4} vs baseline design {:.4}",
            d.mean.rmse, b.mean.rmse
        );
    }
    // A design's L1 beside that of path tracing of its own cost.
    let against_pt = |name: &str| {
        let m = e.method(name)?;
        let pt = e.method(m.equal_time.as_deref()?)?;
        Some(format!(
            "{:.4} vs equal-time path tracing {} {:.4}",
            m.mean.l1,
            pt.name.trim_start_matches("pt-equal-time "),
            pt.mean.l1
        ))
    };
    if let (Some(d), Some(dt), Some(sh)) = (
        against_pt("nprt-dsep"),
        against_pt("nprt-dsep+direct"),
        l1("sh-prt-9"),
    ) {
        println!("headline: L1 D/S {d}; D/S with traced direct light {dt}; SH PRT (9) {sh:.4}");
    }
    let checks = e.checks();
    let count = |v: Verdict| checks.iter().filter(|c| c.verdict == v).count();
    println!(
        "the paper's claims here: {} hold, {} fail, {} not resolved by the test views (see the report)",
        count(Verdict::Holds),
        count(Verdict::Fails),
        count(Verdict::Unresolved)
    );
}
