//! `nprt`: the command-line front end of the pipeline. It parses arguments, calls the stage
//! crates and reports; it owns no rendering or scene logic of its own.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use glam::Vec3;
use nprt_scene::{load_scene, procedural, SceneOptions};
use nprt_trace::{render, Frame, PixelFilter, RenderSettings, TraceScene};

#[derive(Parser)]
#[command(
    name = "nprt",
    version,
    about = "Neural precomputed radiance transfer: path-traced data, per-scene networks, relighting"
)]
struct Cli {
    /// Worker threads (default: all cores).
    #[arg(long, global = true)]
    threads: Option<usize>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Path-trace a scene through its own sensor and film (box pixel filter, the integrator's
    /// max_depth) and write every layer to one OpenEXR file; prints time and samples/s.
    Reference(ReferenceArgs),
    /// Run the pipeline on the built-in scene and lighting, writing images and a summary.
    /// Today: reference renders of builtin:room under the built-in sky and an indoor map.
    Demo(DemoArgs),
}

#[derive(clap::Args)]
struct ReferenceArgs {
    /// Scene: a Mitsuba 3 .xml, a glTF .gltf/.glb, a .ply/.obj mesh, or builtin:room.
    scene: String,
    /// Output OpenEXR file (radiance as R,G,B plus direct.*, position.*, normal.*, view.*,
    /// kd.*, ks.*, alpha, mask).
    #[arg(long)]
    out: PathBuf,
    /// Samples per pixel (default: the scene's sampler, else 64).
    #[arg(long)]
    spp: Option<u32>,
    /// Set a Mitsuba `<default>` parameter, e.g. --set envmap=maps/park.exr (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
    /// Light with this map instead of the scene's: an .exr/.hdr file,
    /// builtin:sky[:ELEV[:AZIM[:TURB]]] or builtin:indoor[:SEED]. Required for scenes without one.
    #[arg(long)]
    envmap: Option<String>,
    /// Rotate the environment about +Y by this many degrees.
    #[arg(long, default_value_t = 0.0)]
    rotate: f32,
    /// Override the integrator's max_depth (Mitsuba's meaning; -1 is unlimited).
    #[arg(long, allow_negative_numbers = true)]
    max_depth: Option<i64>,
    /// Override the film size.
    #[arg(long, requires = "height")]
    width: Option<u32>,
    #[arg(long, requires = "width")]
    height: Option<u32>,
    /// Random seed; the same seed gives the same image on any number of threads.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Also write a tone-mapped (clamped sRGB) PNG preview here.
    #[arg(long)]
    png: Option<PathBuf>,
    /// Trace every sample through the pixel centre (the dataset convention) instead of
    /// box-filtering over the pixel.
    #[arg(long)]
    centre: bool,
}

#[derive(clap::Args)]
struct DemoArgs {
    /// Output folder.
    #[arg(long, default_value = "nprt-demo")]
    out: PathBuf,
    /// Samples per pixel of the demo renders.
    #[arg(long, default_value_t = 64)]
    spp: u32,
}

fn main() {
    let cli = Cli::parse();
    if let Err(e) = run(cli) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(cli: Cli) -> Result<()> {
    if let Some(n) = cli.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("cannot set up worker threads")?;
    }
    match cli.command {
        Command::Reference(a) => reference(a),
        Command::Demo(a) => demo(a),
    }
}

fn parse_set(items: &[String]) -> Result<Vec<(String, String)>> {
    items
        .iter()
        .map(|s| match s.split_once('=') {
            Some((k, v)) if !k.is_empty() => Ok((k.to_string(), v.to_string())),
            _ => bail!("--set expects NAME=VALUE, got '{s}'"),
        })
        .collect()
}

fn reference(a: ReferenceArgs) -> Result<()> {
    let t0 = Instant::now();
    let opts = SceneOptions {
        set: parse_set(&a.set)?,
    };
    let scene = load_scene(&a.scene, &opts)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let env = match (&a.envmap, &scene.envmap) {
        (Some(spec), _) => procedural::open_envmap(spec)?,
        (None, Some(env)) => env.clone(),
        (None, None) => bail!(
            "scene '{}' has no environment emitter; give one with --envmap",
            a.scene
        ),
    }
    .rotated_y(a.rotate);
    if env.clamped_negative() > 0 {
        eprintln!(
            "warning: environment map '{}': {} negative texel channels clamped to 0",
            env.name(),
            env.clamped_negative()
        );
    }
    let mut camera = scene.camera.clone().unwrap_or_else(|| {
        eprintln!(
            "note: scene '{}' has no camera; framing its bounds from +Z",
            a.scene
        );
        scene.framing_camera()
    });
    if let (Some(w), Some(h)) = (a.width, a.height) {
        camera = camera.with_resolution(w, h);
    }
    let max_depth = match a.max_depth {
        Some(d) if d < 0 => None,
        Some(d) => Some(d as u32),
        None => scene.max_depth,
    };
    let settings = RenderSettings {
        spp: a.spp.or(scene.spp).unwrap_or(64).max(1),
        max_depth,
        rr_depth: scene.rr_depth,
        seed: a.seed,
        filter: if a.centre {
            PixelFilter::Centre
        } else {
            PixelFilter::Box
        },
        progress: true,
    };
    check_writable(&a.out)?;
    let ts = TraceScene::new(&scene);
    let setup = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let frame = render(&ts, &camera, &env, &settings);
    let secs = t1.elapsed().as_secs_f64();
    frame.write_exr(&a.out)?;
    if let Some(png) = &a.png {
        write_png(&frame, png)?;
    }
    let samples = camera.width as f64 * camera.height as f64 * settings.spp as f64;
    let m = frame.mean();
    println!(
        "rendered {}×{} at {} spp (max_depth {}) in {secs:.3} s ({:.3} Msamples/s; scene load + BVH {setup:.3} s), {} triangles",
        camera.width,
        camera.height,
        settings.spp,
        max_depth.map_or("unlimited".into(), |d| d.to_string()),
        samples / secs / 1e6,
        scene.triangle_count(),
    );
    println!(
        "mean radiance {:.5} {:.5} {:.5}; wrote {}",
        m.x,
        m.y,
        m.z,
        a.out.display()
    );
    Ok(())
}

/// Fails early, before a long render, if `path` cannot be written.
fn check_writable(path: &Path) -> Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create output folder '{}'", dir.display()))?;
    let probe = dir.join(format!(".nprt-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"")
        .with_context(|| format!("output folder '{}' is not writable", dir.display()))?;
    std::fs::remove_file(&probe).ok();
    Ok(())
}

/// Clamped sRGB preview of the radiance.
fn write_png(frame: &Frame, path: &Path) -> Result<()> {
    let encode = |c: f32| {
        let c = c.clamp(0.0, 1.0);
        let s = if c <= 0.0031308 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0 + 0.5) as u8
    };
    let img = image::RgbImage::from_fn(frame.width as u32, frame.height as u32, |x, y| {
        let v: Vec3 = frame.radiance[y as usize * frame.width + x as usize];
        image::Rgb([encode(v.x), encode(v.y), encode(v.z)])
    });
    let tmp = path.with_extension("png.tmp");
    img.save_with_format(&tmp, image::ImageFormat::Png)
        .with_context(|| format!("cannot write '{}'", tmp.display()))?;
    std::fs::rename(&tmp, path)
        .with_context(|| format!("cannot move '{}' into place", path.display()))
}

fn demo(a: DemoArgs) -> Result<()> {
    let scene = load_scene("builtin:room", &SceneOptions::default())?;
    let camera = scene
        .camera
        .clone()
        .context("built-in scene has a camera")?;
    check_writable(&a.out.join("x"))?;
    let ts = TraceScene::new(&scene);
    println!(
        "nprt demo: builtin:room ({} triangles), {}×{}, {} spp",
        scene.triangle_count(),
        camera.width,
        camera.height,
        a.spp
    );
    for (name, spec) in [("sky", "builtin:sky"), ("indoor", "builtin:indoor:1")] {
        let env = procedural::open_envmap(spec)?;
        let settings = RenderSettings {
            spp: a.spp,
            max_depth: scene.max_depth,
            rr_depth: scene.rr_depth,
            seed: 1,
            filter: PixelFilter::Box,
            progress: true,
        };
        let t = Instant::now();
        let frame = render(&ts, &camera, &env, &settings);
        let secs = t.elapsed().as_secs_f64();
        let exr = a.out.join(format!("room-{name}.exr"));
        let png = a.out.join(format!("room-{name}.png"));
        frame.write_exr(&exr)?;
        write_png(&frame, &png)?;
        let samples = camera.width as f64 * camera.height as f64 * a.spp as f64;
        println!(
            "  {spec:<18} {secs:6.2} s, {:.3} Msamples/s -> {}",
            samples / secs / 1e6,
            png.display()
        );
    }
    println!("demo images in {}", a.out.display());
    Ok(())
}
