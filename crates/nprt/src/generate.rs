//! `nprt generate`: flags for rendering a dataset; the work is `nprt_data::generate`.

use std::path::PathBuf;

use anyhow::Result;
use nprt_data::dataset::{Jitter, TransferBasis};
use nprt_data::{generate, CameraChoice, GenerateOptions, ViewSpec};
use nprt_net::{Compute, Engine, RECIPE};

use crate::flags::{parse_shard, parse_vec3, print_warnings, Resolution};

/// The defaults every flag shows, from the one place that states them.
fn d() -> ViewSpec {
    GenerateOptions::default().views
}

#[derive(clap::Args)]
pub struct GenerateArgs {
    /// Scene: builtin:room, or a Mitsuba .xml / glTF / mesh file (then give the camera volume
    /// unless the scene has a sidecar NAME.camera.json). The scene's own lighting is not read.
    #[arg(long)]
    scene: String,
    /// Environment maps: a folder of .exr/.hdr lat-long maps (a fifth held out for the test
    /// views), or `builtin`: a fresh procedural lighting for every view (random sun and sky,
    /// or indoor windows and lamps), the test views' never seen in training.
    #[arg(long)]
    envmaps: String,
    /// Dataset folder; re-running with the same settings resumes it.
    #[arg(long)]
    out: PathBuf,
    /// Training views (the paper: 3000). Defaults take ~7 min for builtin:room on a 2-core CPU.
    #[arg(long, default_value_t = d().train_views)]
    train_views: u64,
    /// Test views, lit only by held-out maps (the paper: 200).
    #[arg(long, default_value_t = d().test_views)]
    test_views: u64,
    /// Training view resolution, N or WxH (the paper: 256).
    #[arg(long, default_value_t = Resolution(d().train_resolution))]
    train_res: Resolution,
    /// Test view resolution, N or WxH (the paper: 400).
    #[arg(long, default_value_t = Resolution(d().test_resolution))]
    test_res: Resolution,
    /// Samples per pixel of the training views, every one through the pixel centre.
    #[arg(long, default_value_t = d().spp)]
    spp: u32,
    /// Samples per pixel of the test views, the references every method is scored against:
    /// rendered as two independent halves (so even), from which `nprt eval` measures the
    /// references' own noise.
    #[arg(long, default_value_t = d().test_spp)]
    test_spp: u32,
    /// Exposure jitter of the training views' maps, in stops: each view's map is scaled by 2^e,
    /// e uniform in ±this (recorded per view in the manifest; test views are never jittered).
    #[arg(long, value_parser = crate::flags::finite_f32, default_value_t = d().jitter.exposure)]
    jitter_exposure: f32,
    /// White-balance jitter of the training views' maps, in stops: red and blue scaled by
    /// 2^r, 2^b (r, b uniform in ±this) against green, at unchanged luminance.
    #[arg(long, value_parser = crate::flags::finite_f32, default_value_t = d().jitter.tint)]
    jitter_tint: f32,
    /// Light each training view by a random mixture of up to this many maps (1 to 8): its own
    /// map and, uniformly 0 to this − 1, others of the training maps, each turned at random
    /// about +Y and scaled by 1/4 to 1 (light adds, so a mixture is a valid lighting). More
    /// varied lighting for the same views; test views keep one held-out map. Default 1: one map
    /// a view, as before (docs/dataset.md).
    #[arg(long, default_value_t = d().mix_maps,
          value_parser = clap::value_parser!(u32).range(1..=nprt_data::dataset::MAX_MIX_MAPS as i64))]
    mix_maps: u32,
    /// Record each training pixel's light transport on the real spherical harmonics of bands
    /// 0..L (sh:L, L ≤ 8: (L+1)² coefficients per channel, its direct part kept apart), from
    /// as many BSDF-sampled paths per pixel as its radiance: a target that holds every
    /// lighting at once, which `nprt train --arch linear --basis sh:L' --targets transfer`
    /// (L' ≤ L) learns. Adds about three quarters to the training views' time; CPU tracer only
    /// (docs/dataset.md). `none` records none. [default: what the recommended recipe trains
    /// on (`nprt train` without --arch) on the CPU tracer, none on the GPU's]
    #[arg(long, value_parser = parse_transfer)]
    transfer: Option<TransferArg>,
    /// Seed of every random choice (cameras, split, rotations, pixels).
    #[arg(long, default_value_t = d().seed)]
    seed: u64,
    /// Maps of the folder held out for testing (default: a fifth, at least one).
    #[arg(long)]
    test_maps: Option<usize>,
    /// With a folder of maps: this share of the training views (0 to 1) is lit by a fresh
    /// procedural lighting of its own instead of a folder map, so a few real maps train among
    /// many lightings; test views keep the folder's held-out maps (recorded in the manifest).
    /// Default 0.5, which improved every error on held-out real maps against 0
    /// (docs/evaluation.md); 0 makes a folder dataset as before mixing existed. Not for
    /// --envmaps builtin.
    #[arg(long, value_parser = crate::flags::finite_f32)]
    mix_builtin: Option<f32>,
    /// Render only views with index ≡ K (mod N), e.g. 0/4 … 3/4 on four machines. Default:
    /// the task of the Slurm job array this runs in (SLURM_ARRAY_TASK_ID of
    /// SLURM_ARRAY_TASK_COUNT; scripts/slurm-generate), else 0/1, the whole dataset.
    #[arg(long, value_parser = parse_shard)]
    shard: Option<(u64, u64)>,
    /// Camera active volume from a JSON file (as a scene's sidecar NAME.camera.json, which is
    /// read by default: docs/dataset.md); overrides the scene's.
    #[arg(long, conflicts_with = "volume_min")]
    camera_volume: Option<PathBuf>,
    /// Camera active volume, min corner x,y,z (overrides the scene's; with --volume-max and
    /// --look).
    #[arg(long, value_parser = parse_vec3, requires_all = ["volume_max", "look"], allow_hyphen_values = true)]
    volume_min: Option<glam::Vec3>,
    /// Camera active volume, max corner x,y,z.
    #[arg(long, value_parser = parse_vec3, requires_all = ["volume_min", "look"], allow_hyphen_values = true)]
    volume_max: Option<glam::Vec3>,
    /// Main view direction x,y,z.
    #[arg(long, value_parser = parse_vec3, requires_all = ["volume_min", "volume_max"], allow_hyphen_values = true)]
    look: Option<glam::Vec3>,
    /// Half-angle of the pyramid of view directions, degrees (default: the volume's; 30 for
    /// corners given by hand).
    #[arg(long, value_parser = crate::flags::finite_f32)]
    spread: Option<f32>,
    /// Horizontal field of view of dataset cameras, degrees (default: the volume's; 60 for
    /// corners given by hand).
    #[arg(long, value_parser = crate::flags::finite_f32)]
    fov: Option<f32>,
    /// Where the views are path traced: cpu, gpu (the same path tracer as a WGSL kernel on
    /// the best GPU adapter, a discrete one first; needs the `gpu` feature), wgpu (any
    /// adapter, Mesa's software lavapipe included) or auto (gpu when a hardware adapter is
    /// found, else the CPU). The two draw different random numbers: the manifest records which
    /// began a dataset, and it is resumed on that one.
    #[arg(long = "device", default_value_t = Compute::Cpu)]
    device: Compute,
}

impl TryFrom<GenerateArgs> for GenerateOptions {
    type Error = anyhow::Error;

    fn try_from(a: GenerateArgs) -> Result<Self> {
        let device = a.device.engine()?.tracer();
        let shard = match a.shard {
            Some(shard) => shard,
            None => nprt_data::shard_from_env()?.unwrap_or((0, 1)),
        };
        Ok(GenerateOptions {
            scene: a.scene,
            envmaps: a.envmaps,
            out: a.out,
            views: ViewSpec {
                train_views: a.train_views,
                test_views: a.test_views,
                train_resolution: a.train_res.0,
                test_resolution: a.test_res.0,
                spp: a.spp,
                test_spp: a.test_spp,
                seed: a.seed,
                jitter: Jitter {
                    exposure: a.jitter_exposure,
                    tint: a.jitter_tint,
                },
                mix_maps: a.mix_maps,
            },
            transfer: match a.transfer {
                Some(TransferArg(t)) => t,
                None => RECIPE.dataset_transfer_on(device),
            },
            test_maps: a.test_maps,
            mix_builtin: a.mix_builtin,
            camera: CameraChoice {
                file: a.camera_volume,
                min: a.volume_min,
                max: a.volume_max,
                look: a.look,
                spread_deg: a.spread,
                fov_deg: a.fov,
            },
            shard,
            device,
            progress: true,
        })
    }
}

/// `--transfer`'s value: a basis, or `none`.
#[derive(Clone, Copy)]
struct TransferArg(Option<TransferBasis>);

fn parse_transfer(s: &str) -> Result<TransferArg, String> {
    TransferBasis::parse_choice(s)
        .map(TransferArg)
        .map_err(|e| format!("{e:#}"))
}

/// Renders the dataset, printing its plan and what was rendered.
pub fn run(opts: &GenerateOptions) -> Result<()> {
    let summary = generate(opts, |p| {
        print_warnings(&p.warnings);
        let s = &p.manifest.settings;
        let transfer = match s.transfer {
            Some(t) => format!("; transfer vectors {t} (what `nprt train` learns without --arch)"),
            None => String::new(),
        };
        println!(
            "dataset {}: {} train views ({}×{}, {} spp) under {} maps, {} test views ({}×{}, {} spp) under {} held-out maps; shard {}/{}; traced on the {}{transfer}",
            opts.out.display(), s.train_views, s.train_resolution[0], s.train_resolution[1], s.spp, s.train_maps.len(),
            s.test_views, s.test_resolution[0], s.test_resolution[1], opts.views.test_spp, s.test_maps.len(), opts.shard.0, opts.shard.1,
            Engine::from(opts.device).name()
        );
    })?;
    for r in &summary.redone {
        eprintln!("redone: {r}");
    }
    if summary.removed_temporaries > 0 {
        eprintln!(
            "removed {} temporary files left by killed runs",
            summary.removed_temporaries
        );
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
