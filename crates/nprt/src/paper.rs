//! `nprt paper`: flags for reproducing the paper's tables; the work is `nprt_paper`.

use std::path::PathBuf;

use anyhow::Result;
use nprt_data::CameraChoice;
use nprt_eval::claim::Verdict;
use nprt_paper::{Budget, Experiment};

use crate::flags::{finite_f64, parse_snapshots, DeviceArg, Snapshots};

#[derive(clap::Args)]
pub struct PaperArgs {
    /// Scene: builtin:room, or a Mitsuba .xml / glTF / mesh file with a camera volume (a sidecar
    /// NAME.camera.json, or --camera-volume). The paper's KITCHEN:
    /// ../shared/scenes/kitchen/scene.xml with --camera-volume docs/kitchen.camera.json.
    #[arg(long, default_value = "builtin:room")]
    scene: String,
    /// Lighting: a folder of .exr/.hdr lat-long maps (some held out for the test views), or
    /// `builtin` (a fresh procedural lighting per view).
    #[arg(long, default_value = "builtin")]
    envmaps: String,
    /// Output folder: dataset/, models/, report/ (paper.html, report.html) and
    /// stage-times.json. Re-running resumes what is done; a folder holding another scene,
    /// lighting or budget is refused.
    #[arg(long)]
    out: PathBuf,
    /// Sizes (docs/paper.md): tiny (test-only, 10 s), small (36 minutes on 2 cores
    /// on KITCHEN), medium (about 5 hours on 2 cores), paper (the paper's: 3000 views of 256², 3200 spp,
    /// 500 epochs; a cluster and a GPU).
    #[arg(long, default_value = "small", value_parser = parse_budget)]
    budget: Budget,
    /// Camera active volume from a JSON file (docs/dataset.md), instead of the scene's sidecar.
    #[arg(long)]
    camera_volume: Option<PathBuf>,
    /// Maps of the --envmaps folder held out for the test views (default: a fifth).
    #[arg(long)]
    test_maps: Option<usize>,
    /// Seed of every random choice (cameras, lightings, samples, initial weights).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Print the `nprt generate` flags of this experiment's dataset and stop: for rendering it
    /// on a cluster first (`scripts/slurm-generate N -- $(nprt paper ... --generate-flags)`),
    /// after which `nprt paper` with the same flags finds it complete (docs/paper.md).
    #[arg(long)]
    generate_flags: bool,
    /// Keep the paper's four designs at these points of their training (minutes of training
    /// time as Nm, epochs as N, comma-separated: e.g. 1m,2m,4m,8m,16m, within the budget's
    /// training) and judge the orderings of Tables 5 and 6 at each, with plots of RMSE and loss
    /// against training time (docs/paper.md). Give it from the first run: a finished training
    /// keeps no points it passed.
    #[arg(long, value_name = "LIST", value_parser = parse_snapshots)]
    snapshots: Option<Snapshots>,
    /// Train every network (the designs, Table 2's ablation, Deep Shading) this many minutes
    /// instead of the budget's, at the budget's sizes: e.g. `--budget small --training-minutes
    /// 16 --snapshots 1m,2m,4m,8m,16m` follows the orderings past small's 4 minutes. Recorded
    /// with the experiment: a folder trained at another length is refused.
    #[arg(long, value_name = "MINUTES", value_parser = finite_f64)]
    training_minutes: Option<f64>,
    #[command(flatten)]
    device: DeviceArg,
}

fn parse_budget(s: &str) -> Result<Budget> {
    s.parse()
}

pub fn command(a: PaperArgs) -> Result<()> {
    let x = Experiment {
        camera: CameraChoice {
            file: a.camera_volume,
            ..CameraChoice::default()
        },
        test_maps: a.test_maps,
        seed: a.seed,
        snapshots: a.snapshots.map(|s| s.0).unwrap_or_default(),
        training_minutes: a.training_minutes,
        ..Experiment::paper(&a.scene, &a.envmaps, &a.out, a.budget, a.device.engine()?)
    };
    if a.generate_flags {
        println!("{}", x.generate_flags()?.join(" "));
        return Ok(());
    }
    let done = x.run()?;
    println!("\n== nprt paper done in {:.0} s", done.seconds);
    if let Some((md, html)) = &done.paper {
        println!(
            "the paper's tables: {} and {}",
            md.display(),
            html.display()
        );
    }
    println!("the evaluation's report: {}", done.report.display());
    let orderings = nprt_paper::orderings::all(&done.evaluation, &done.ablation);
    for o in &orderings {
        println!(
            "{:<13} {}: {}",
            format!("{}:", o.verdict().word()),
            o.table,
            o.statement
        );
    }
    let count = |v: Verdict| orderings.iter().filter(|o| o.verdict() == v).count();
    println!(
        "the paper's orderings here: {} hold, {} fail, {} not resolved by the test views",
        count(Verdict::Holds),
        count(Verdict::Fails),
        count(Verdict::Unresolved)
    );
    Ok(())
}
