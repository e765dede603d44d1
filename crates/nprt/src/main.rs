//! `nprt`: the command-line front end of the pipeline. It parses arguments, calls the stage
//! crates and reports; it owns no rendering or scene logic of its own.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use nprt_scene::{load_scene, SceneOptions};
use nprt_trace::{render, PixelFilter, RenderSettings, TraceScene};

mod demo;
mod evaluation;
mod learn;
mod relight;

// Training allocates and frees large tensors every step; glibc's allocator returns that memory
// to the OS and page-faults it back each time (measured: 8% of a training step).
#[global_allocator]
static ALLOC: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[derive(Parser)]
#[command(
    name = "nprt",
    version,
    args_override_self = true,
    about = "Neural precomputed radiance transfer: path-traced data, per-scene networks, relighting"
)]
struct Cli {
    /// Worker threads (default: all cores).
    #[arg(long, global = true)]
    threads: Option<usize>,
    #[command(subcommand)]
    command: Command,
}

/// `--device`, shared by every command that runs the networks.
#[derive(clap::Args, Clone, Copy)]
pub(crate) struct DeviceArg {
    /// Where the networks run: cpu, gpu (an NVIDIA GPU through CUDA; an error if none is found),
    /// wgpu (any Vulkan or Metal GPU through wgpu, Mesa's software Vulkan driver included,
    /// which is how the GPU path is tested without a GPU) or auto (the CUDA GPU when one is
    /// found, else the CPU). A model folder is the same whichever trained it.
    #[arg(long = "device", default_value = "auto")]
    pub(crate) compute: nprt_net::Compute,
}

impl DeviceArg {
    pub(crate) fn device(self) -> Result<nprt_net::Device> {
        self.compute.device()
    }
}

/// How long a training run lasts and how its learning rate moves, shared by both trainings.
#[derive(clap::Args, Clone, Copy)]
pub(crate) struct RunLength {
    /// Passes over the training data [default: 20, or as many as fit with --minutes].
    #[arg(long)]
    pub(crate) epochs: Option<usize>,
    /// Wall-clock budget: stop when the run's training time reaches this many minutes (or
    /// after --epochs if given, whichever comes first). The same command continues a stopped
    /// run up to the budget.
    #[arg(long)]
    pub(crate) minutes: Option<f64>,
    /// Learning-rate schedule: paper (--lr throughout, as the paper) or cosine (warm-up over
    /// the first 2% of the run, then a cosine decay to 5% of --lr at its end: the last epoch,
    /// or the end of --minutes). A cosine run keeps its length: it cannot be lengthened later.
    /// [default: cosine for train, paper for train-deep-shading]
    #[arg(long)]
    pub(crate) schedule: Option<nprt_net::LrSchedule>,
}

impl RunLength {
    /// `defaults` with this run's length and schedule.
    pub(crate) fn apply(self, defaults: nprt_net::Schedule) -> nprt_net::Schedule {
        let epochs = match (self.epochs, self.minutes) {
            (Some(e), _) => e,
            (None, Some(_)) => usize::MAX,
            (None, None) => defaults.epochs,
        };
        nprt_net::Schedule {
            epochs,
            minutes: self.minutes,
            lr_schedule: self.schedule.unwrap_or(defaults.lr_schedule),
            ..defaults
        }
    }
}

#[derive(Subcommand)]
enum Command {
    /// Path-trace a scene through its own sensor and film (box pixel filter, the integrator's
    /// max_depth) and write every layer to one OpenEXR file; prints time and samples/s.
    Reference(ReferenceArgs),
    /// The whole pipeline on the built-in scene and lighting: generate a dataset, train the four
    /// designs and Deep Shading, evaluate them against the baselines, relight a camera path
    /// under held-out lighting. About 15 minutes on 2 cores; --quick under a minute.
    Demo(demo::DemoArgs),
    /// Render a training dataset: G-buffers and radiance of many views under many lightings
    /// (documented in docs/dataset.md). Resumable; shards may run at once into one folder.
    Generate(GenerateArgs),
    /// Inspect datasets.
    #[command(subcommand)]
    Dataset(DatasetCommand),
    /// Describe networks.
    #[command(subcommand)]
    Model(ModelCommand),
    /// Train one Neural PRT design (light encoder and transport, jointly) on a dataset; writes a
    /// model folder with weights, config, loss.csv, loss.png and a resumable checkpoint.
    Train(learn::TrainArgs),
    /// Benchmarks.
    #[command(subcommand)]
    Bench(learn::BenchCommand),
    /// Relight a camera path with a trained model under a lighting schedule: primary rays for
    /// the G-buffer, the encoder once per lighting change, the network on foreground pixels.
    /// Writes PNG frames (EXR on request), an animation and per-frame timings.
    Render(relight::RenderArgs),
    /// Evaluate trained designs against the paper's baselines (path tracing at 5 spp and at
    /// equal time, denoised when Open Image Denoise is installed, SH PRT with 9 and 25
    /// coefficients, Deep Shading) on a dataset's test views: metrics, error analysis, timings,
    /// images; writes a Markdown and a self-contained HTML report.
    Eval(evaluation::EvalArgs),
    /// Train the Deep Shading baseline (a per-scene U-Net on G-buffer images, with the light
    /// code at its bottleneck) on a dataset.
    TrainDeepShading(evaluation::DeepShadingArgs),
}

#[derive(Subcommand)]
enum ModelCommand {
    /// Print the layer table and parameter counts of a design (transport counts exclude the
    /// encoder, as the paper's Table 1).
    Info(learn::ModelInfoArgs),
}

#[derive(Subcommand)]
enum DatasetCommand {
    /// Report completeness and problems of a dataset folder; exits 1 unless complete.
    Verify {
        /// Dataset folder (holding manifest.json).
        dir: PathBuf,
    },
}

#[derive(clap::Args)]
pub(crate) struct GenerateArgs {
    /// Scene: builtin:room, or a Mitsuba .xml / glTF / mesh file (then give the camera volume).
    #[arg(long)]
    pub(crate) scene: String,
    /// Environment maps: a folder of .exr/.hdr lat-long maps (a fifth held out for the test
    /// views), or `builtin`: a fresh procedural lighting for every view (random sun and sky,
    /// or indoor windows and lamps), the test views' never seen in training.
    #[arg(long)]
    pub(crate) envmaps: String,
    /// Dataset folder; re-running with the same settings resumes it.
    #[arg(long)]
    pub(crate) out: PathBuf,
    /// Training views (the paper: 3000). Defaults take ~7 min for builtin:room on a 2-core CPU.
    #[arg(long, default_value_t = 400)]
    pub(crate) train_views: u64,
    /// Test views, lit only by held-out maps (the paper: 200).
    #[arg(long, default_value_t = 40)]
    pub(crate) test_views: u64,
    /// Training view resolution, N or WxH (the paper: 256).
    #[arg(long, default_value = "128", value_parser = parse_resolution)]
    pub(crate) train_res: [u32; 2],
    /// Test view resolution, N or WxH (the paper: 400).
    #[arg(long, default_value = "128", value_parser = parse_resolution)]
    pub(crate) test_res: [u32; 2],
    /// Samples per pixel of the training views, every one through the pixel centre.
    #[arg(long, default_value_t = 64)]
    pub(crate) spp: u32,
    /// Samples per pixel of the test views, the references every method is scored against:
    /// rendered as two independent halves (so even), from which `nprt eval` measures the
    /// references' own noise.
    #[arg(long, default_value_t = 1024)]
    pub(crate) test_spp: u32,
    /// Exposure jitter of the training views' maps, in stops: each view's map is scaled by 2^e,
    /// e uniform in ±this (recorded per view in the manifest; test views are never jittered).
    #[arg(long, default_value_t = 1.0)]
    pub(crate) jitter_exposure: f32,
    /// White-balance jitter of the training views' maps, in stops: red and blue scaled by
    /// 2^r, 2^b (r, b uniform in ±this) against green, at unchanged luminance.
    #[arg(long, default_value_t = 0.3)]
    pub(crate) jitter_tint: f32,
    /// Seed of every random choice (cameras, split, rotations, pixels).
    #[arg(long, default_value_t = 0)]
    pub(crate) seed: u64,
    /// Maps of the folder held out for testing (default: a fifth, at least one).
    #[arg(long)]
    pub(crate) test_maps: Option<usize>,
    /// With a folder of maps: this share of the training views (0 to 1) is lit by a fresh
    /// procedural lighting of its own instead of a folder map, so a few real maps train among
    /// many lightings; test views keep the folder's held-out maps (recorded in the manifest).
    /// 0.5 improved every error on held-out real maps (docs/evaluation.md); 0 makes the
    /// dataset a folder made before mixing existed.
    #[arg(long, default_value_t = 0.0)]
    pub(crate) mix_builtin: f32,
    /// Render only views with index ≡ K (mod N), e.g. 0/4 … 3/4 on four machines.
    #[arg(long, default_value = "0/1", value_parser = parse_shard)]
    pub(crate) shard: (u64, u64),
    /// Camera active volume from a JSON file (as a scene's sidecar NAME.camera.json, which is
    /// read by default: docs/dataset.md); overrides the scene's.
    #[arg(long, conflicts_with = "volume_min")]
    pub(crate) camera_volume: Option<std::path::PathBuf>,
    /// Camera active volume, min corner x,y,z (overrides the scene's).
    #[arg(long, value_parser = parse_vec3, requires_all = ["volume_max", "look"], allow_hyphen_values = true)]
    pub(crate) volume_min: Option<glam::Vec3>,
    /// Camera active volume, max corner x,y,z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) volume_max: Option<glam::Vec3>,
    /// Main view direction x,y,z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) look: Option<glam::Vec3>,
    /// Half-angle of the pyramid of view directions, degrees.
    #[arg(long, default_value_t = 30.0)]
    pub(crate) spread: f32,
    /// Horizontal field of view of dataset cameras, degrees.
    #[arg(long, default_value_t = 60.0)]
    pub(crate) fov: f32,
}

pub(crate) fn parse_resolution(s: &str) -> Result<[u32; 2], String> {
    let parse = |t: &str| {
        t.parse::<u32>()
            .ok()
            .filter(|&v| v > 0)
            .ok_or(format!("'{s}' is not N or WxH with positive sizes"))
    };
    match s.split_once('x') {
        Some((w, h)) => Ok([parse(w)?, parse(h)?]),
        None => parse(s).map(|n| [n, n]),
    }
}

fn parse_shard(s: &str) -> Result<(u64, u64), String> {
    let bad = || format!("'{s}' is not K/N with 0 ≤ K < N");
    let (k, n) = s.split_once('/').ok_or_else(bad)?;
    let (k, n) = (
        k.parse::<u64>().map_err(|_| bad())?,
        n.parse::<u64>().map_err(|_| bad())?,
    );
    if n == 0 || k >= n {
        return Err(bad());
    }
    Ok((k, n))
}

fn parse_vec3(s: &str) -> Result<glam::Vec3, String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|t| t.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("'{s}' is not x,y,z"))?;
    match v.as_slice() {
        [x, y, z] => Ok(glam::Vec3::new(*x, *y, *z)),
        _ => Err(format!("'{s}' is not x,y,z")),
    }
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

fn main() {
    // A closed pipe (`nprt … | head`) ends the process quietly, as for other command-line
    // tools, instead of panicking in println!.
    // SAFETY: restores the default disposition of one signal before any thread starts.
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse();
    let result = run(cli);
    nprt_net::finish();
    if let Err(e) = result {
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
        Command::Demo(a) => demo::demo(a),
        Command::Generate(a) => generate(a),
        Command::Dataset(DatasetCommand::Verify { dir }) => verify(&dir),
        Command::Model(ModelCommand::Info(a)) => learn::model_info(a),
        Command::Train(a) => learn::train(a),
        Command::Bench(c) => learn::bench(c),
        Command::Render(a) => relight::render(a),
        Command::Eval(a) => evaluation::eval(a).map(|_| ()),
        Command::TrainDeepShading(a) => evaluation::train_deep_shading(a),
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
        (Some(spec), _) => nprt_scene::open_envmap(spec)?,
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
    nprt_io::check_writable(&a.out)?;
    let loaded = t0.elapsed().as_secs_f64();
    let ts = TraceScene::new(&scene);
    let setup = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let frame = render(&ts, &camera, &env, &settings);
    let secs = t1.elapsed().as_secs_f64();
    frame.write_exr(&a.out)?;
    if let Some(png) = &a.png {
        nprt_render::write_png(&frame.radiance, frame.width, frame.height, 0.0, png)?;
    }
    let samples = camera.width as f64 * camera.height as f64 * settings.spp as f64;
    let m = frame.mean();
    println!(
        "rendered {}×{} at {} spp (max_depth {}) in {secs:.3} s ({:.3} Msamples/s; scene load {loaded:.3} s + BVH {:.3} s), {} triangles",
        camera.width,
        camera.height,
        settings.spp,
        max_depth.map_or("unlimited".into(), |d| d.to_string()),
        samples / secs / 1e6,
        setup - loaded,
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

pub(crate) fn generate(a: GenerateArgs) -> Result<()> {
    use nprt_data::{dataset, lighting};
    let scene = load_scene(&a.scene, &SceneOptions::default())?;
    let volume = match (a.volume_min, a.volume_max, a.look) {
        (Some(min), Some(max), Some(look)) => {
            if !min.cmple(max).all() || look.length() == 0.0 {
                bail!("--volume-min must not exceed --volume-max, and --look must be non-zero");
            }
            nprt_scene::CameraVolume {
                min,
                max,
                look: look.normalize(),
                spread_deg: a.spread,
                fov_deg: a.fov,
            }
        }
        _ => match &a.camera_volume {
            Some(file) => nprt_scene::CameraVolume::load(file)?,
            None => scene.camera_volume.clone().with_context(|| {
                format!(
                    "scene '{}' carries no camera volume (no sidecar '{}'); give --camera-volume FILE or --volume-min, --volume-max and --look",
                    a.scene,
                    nprt_scene::CameraVolume::sidecar_of(std::path::Path::new(&a.scene)).display()
                )
            })?,
        },
    };
    let (specs, assignment) = lighting::choose(
        &a.envmaps,
        a.train_views,
        a.test_views,
        a.test_maps,
        a.mix_builtin,
        a.seed,
    )?;
    let maps = lighting::load_all(&specs)?;
    for m in maps.iter().filter(|m| m.clamped_negative() > 0) {
        eprintln!(
            "warning: environment map '{}': {} negative texel channels clamped to 0",
            m.name(),
            m.clamped_negative()
        );
    }
    let source = nprt_data::dataset::scene_source(&a.scene)?;
    let request = nprt_data::Request {
        scene_spec: a.scene.clone(),
        scene: &scene,
        scene_source: source,
        volume,
        lighting: assignment,
        map_specs: specs,
        maps,
        train_views: a.train_views,
        test_views: a.test_views,
        train_resolution: a.train_res,
        test_resolution: a.test_res,
        spp: a.spp,
        test_spp: a.test_spp,
        seed: a.seed,
        jitter: nprt_data::dataset::Jitter {
            exposure: a.jitter_exposure,
            tint: a.jitter_tint,
        },
    };
    let ts = TraceScene::new(&scene);
    // Planning validates the split and places cameras; only then is anything written.
    let manifest = dataset::plan(&request, &ts)?;
    dataset::prepare(&a.out, &manifest)?;
    let s = &manifest.settings;
    println!(
        "dataset {}: {} train views ({}×{}, {} spp) under {} maps, {} test views ({}×{}, {} spp) under {} held-out maps; shard {}/{}",
        a.out.display(), s.train_views, s.train_resolution[0], s.train_resolution[1], s.spp, s.train_maps.len(),
        s.test_views, s.test_resolution[0], s.test_resolution[1], a.test_spp, s.test_maps.len(), a.shard.0, a.shard.1
    );
    let summary = dataset::run(&ts, &request.maps, &manifest, &a.out, a.shard, true)?;
    for r in &summary.redone {
        eprintln!("redone: {r}");
    }
    let per_view = if summary.rendered > 0 {
        summary.seconds / summary.rendered as f64
    } else {
        0.0
    };
    println!(
        "rendered {} views in {:.1} s ({:.3} s per view, {:.3} Msamples/s), {} already complete",
        summary.rendered,
        summary.seconds,
        per_view,
        summary.samples / summary.seconds.max(1e-9) / 1e6,
        summary.skipped
    );
    Ok(())
}

fn verify(dir: &Path) -> Result<()> {
    let r = nprt_data::dataset::verify(dir)?;
    for f in &r.corrupt {
        println!("corrupt: {f}");
    }
    for f in r.missing.iter().take(20) {
        println!("missing: {f}");
    }
    if r.missing.len() > 20 {
        println!("missing: … and {} more", r.missing.len() - 20);
    }
    println!(
        "{}: {} of {} views complete, {} missing, {} corrupt",
        dir.display(),
        r.complete,
        r.views,
        r.missing.len(),
        r.corrupt.len()
    );
    if r.complete != r.views {
        bail!("dataset '{}' is incomplete", dir.display());
    }
    Ok(())
}
