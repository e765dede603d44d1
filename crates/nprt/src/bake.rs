//! `nprt bake`: flags for baking a scene into a relit model in one command; the work is
//! `nprt_paper::bake`.

use std::path::PathBuf;

use anyhow::Result;
use nprt_data::CameraChoice;
use nprt_paper::bake::{Bake, Baked, Quality};

use crate::flags::{finite_f64, DeviceArg};

#[derive(clap::Args)]
pub struct BakeArgs {
    /// Scene: builtin:room, or a Mitsuba .xml / glTF / mesh file with a camera volume (a
    /// sidecar NAME.camera.json, or --camera-volume; docs/dataset.md).
    scene: String,
    /// Lighting: a folder of .exr/.hdr lat-long maps (a fifth held out to check the model on),
    /// or `builtin` (a fresh procedural lighting per view).
    #[arg(long)]
    envmaps: String,
    /// Output folder: dataset/, model/ (the model, for `nprt view` and `nprt render`),
    /// report/ (the check against path tracing), preview.png and comparison.png (the model
    /// beside the path-traced reference). Re-running resumes where a run stopped; a folder
    /// holding another bake is refused.
    #[arg(long)]
    out: PathBuf,
    /// Sizes: draft (builtin:room in under 10 minutes on 2 cores: 150 views of 64², 4 minutes
    /// of training), good (400 views, 12 minutes) or best (1,000 views of 96², 40 minutes); a
    /// camera volume spanning much of the scene gets up to 3× the views (docs/commands.md);
    /// tiny is for tests (seconds, deciding nothing).
    #[arg(long, default_value = "draft", value_parser = parse_quality)]
    quality: Quality,
    /// Minutes of training instead of the quality's.
    #[arg(long, value_parser = finite_f64)]
    minutes: Option<f64>,
    /// Passes over the training data instead of minutes: reproducible bit for bit, where a
    /// time budget is not.
    #[arg(long, conflicts_with = "minutes", value_parser = clap::value_parser!(u32).range(1..=100_000))]
    epochs: Option<u32>,
    /// Camera active volume from a JSON file, instead of the scene's sidecar.
    #[arg(long)]
    camera_volume: Option<PathBuf>,
    /// Maps of the --envmaps folder held out for the check (default: a fifth).
    #[arg(long)]
    test_maps: Option<usize>,
    /// Seed of every random choice (cameras, lightings, samples, initial weights).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Train in a window (`nprt view --train`'s, keys and all), watching the model learn beside
    /// the path-traced reference; the bake goes on to its check once the run's minutes are
    /// trained and the window is closed. Closed earlier, the bake stops with the model saved
    /// (the same command continues it). Needs the `gpu` feature.
    #[arg(long, conflicts_with = "epochs")]
    view: bool,
    /// With --view: keys pressed at given times, as `nprt view --keys` (scripts and tests).
    #[arg(long, requires = "view", value_delimiter = ',', value_parser = crate::view::parse_key)]
    keys: Vec<(f64, nprt_render::ScriptedKey)>,
    #[command(flatten)]
    device: DeviceArg,
}

fn parse_quality(s: &str) -> Result<Quality> {
    s.parse()
}

pub fn command(a: BakeArgs) -> Result<()> {
    let bake = Bake {
        minutes: a.minutes,
        epochs: a.epochs.map(|e| e as usize),
        camera: CameraChoice {
            file: a.camera_volume,
            ..CameraChoice::default()
        },
        test_maps: a.test_maps,
        seed: a.seed,
        view: a
            .view
            .then(|| crate::view::training_window(a.keys))
            .transpose()?,
        ..Bake::new(&a.scene, &a.envmaps, &a.out, a.quality, a.device.engine()?)
    };
    let baked = bake.run()?;
    print_summary(&bake, &baked);
    Ok(())
}

/// Where the model is, how it did against path tracing on the held-out views, and the commands
/// that use it.
fn print_summary(bake: &Bake, b: &Baked) {
    println!("model '{}': {}", b.model.display(), b.description);
    println!(
        "checked on {} held-out views against path-traced references:",
        b.views
    );
    println!(
        "  {:<44} {:>8} {:>8} {:>8} {:>10}",
        "", "L1", "RMSE", "dSSIM", "ms / view"
    );
    let row = |name: &str, m: &nprt_eval::MethodResult| {
        println!(
            "  {:<44} {:>8.4} {:>8.4} {:>8.4} {:>10.1}",
            name, m.mean.l1, m.mean.rmse, m.mean.dssim, m.ms_per_view
        )
    };
    row("this model", &b.model_row);
    if let Some(pt) = &b.path_tracing {
        row(&format!("{} (its cost)", pt.name), pt);
        // "12% ahead" where the model's error is lower, "3% behind" where it is higher.
        let ahead = |a: f64, b: f64| match 100.0 * (b - a) / b {
            d if d >= 0.0 => format!("{d:.0}% ahead"),
            d => format!("{:.0}% behind", -d),
        };
        let m = &b.model_row.mean;
        println!(
            "  against path tracing of its cost: {} in L1, {} in RMSE, {} in dSSIM",
            ahead(m.l1, pt.mean.l1),
            ahead(m.rmse, pt.mean.rmse),
            ahead(m.dssim, pt.mean.dssim),
        );
    }
    if let Some(c) = &b.check {
        let which = match c.denoise {
            true => "denoised by OIDN, which measured better than raw",
            false => "raw, which measured better than denoised by OIDN",
        };
        println!(
            "  its traced direct light {which} (L1 / RMSE / dSSIM raw {:.4} / {:.4} / {:.4}, denoised {:.4} / {:.4} / {:.4}; kept as model/{})",
            c.raw[0], c.raw[1], c.raw[2], c.denoised[0], c.denoised[1], c.denoised[2],
            nprt_render::DENOISE_CHECK_FILE
        );
    }
    let [r, g, bl] = b.model_row.level;
    println!("  level R / G / B {r:.3} / {g:.3} / {bl:.3} (the reference's is 1)");
    println!(
        "the model beside the reference: '{}'; the check's report: '{}'",
        b.comparison.display(),
        b.report.display()
    );
    let model = b.model.display();
    let maps = b.held_out_maps.join(",");
    println!("use it (under the held-out maps it never saw):");
    println!("  nprt view {model} --maps {maps}");
    println!(
        "  nprt render --model {model} --lighting {maps} --out {}",
        bake.out.join("frames").display()
    );
    println!("baked in {:.1} minutes", b.seconds / 60.0);
}
