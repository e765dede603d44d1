//! `nprt demo`: the whole pipeline on the built-in scene and lighting, sized for a laptop CPU;
//! the work is `nprt_paper::Experiment::demo`, the same pipeline `nprt paper` runs.

use std::path::PathBuf;

use anyhow::Result;
use nprt_eval::claim::Verdict;
use nprt_eval::Evaluation;
use nprt_paper::Experiment;

use crate::flags::DeviceArg;

#[derive(clap::Args)]
pub struct DemoArgs {
    /// Output folder (dataset, models, report, relit frames). Re-running resumes what is done.
    #[arg(long, default_value = "nprt-demo")]
    out: PathBuf,
    /// Tiny sizes (under a minute on 2 cores, `nprt paper`'s tiny budget): checks the
    /// pipeline, not the method.
    #[arg(long)]
    quick: bool,
    #[command(flatten)]
    device: DeviceArg,
}

pub fn run(a: DemoArgs) -> Result<()> {
    let done = Experiment::demo(&a.out, a.quick, a.device.engine()?).run()?;
    println!("\n== nprt demo done in {:.0} s", done.seconds);
    println!("report: {}", done.report.display());
    if let Some(frames) = &done.relit {
        println!("relit frames: {}", frames.display());
    }
    print_headline(&done.evaluation);
    Ok(())
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
