//! `nprt view`: flags for the interactive viewer; the window is `nprt_render::view`.

use std::path::PathBuf;

use anyhow::Result;
use nprt_render::ScriptedKey;

use crate::flags::{design_names, DeviceArg, Resolution};

/// The lightings M switches among when neither `--maps` nor a dataset gives them.
#[cfg(feature = "gpu")]
const DEFAULT_MAPS: [&str; 5] = [
    "builtin:sky:30:250:3",
    "builtin:sky:60:90:2",
    "builtin:sky:12:200:6",
    "builtin:indoor:9",
    "builtin:indoor:3",
];

#[derive(clap::Args)]
pub struct ViewArgs {
    /// Trained model folders of one scene (from `nprt train`); Tab switches among them.
    #[arg(required_unless_present = "train", conflicts_with = "train")]
    models: Vec<PathBuf>,
    /// Train a model on this dataset folder (from `nprt generate`) while the window shows it:
    /// the window opens at once on the dataset's scene, in its camera volume, under its maps
    /// (held-out ones first); the view relights with the newest weights every 2 seconds of
    /// training. Space pauses and resumes training, K saves, X lengthens the run; closing the
    /// window saves the model (resumable). Without --arch: the recommended recipe.
    #[arg(long, value_name = "DATA")]
    train: Option<PathBuf>,
    /// With --train: the model folder (a run there continues) [default: DATA-model beside the
    /// dataset].
    #[arg(long, requires = "train", value_name = "MODEL")]
    out: Option<PathBuf>,
    /// With --train: minutes of training, 0.001 to 1,000,000 [default: the model folder's own
    /// run's, else 10].
    #[arg(long, requires = "train", value_parser = crate::flags::finite_f64)]
    minutes: Option<f64>,
    /// With --train: the transport design, with its own defaults (as `nprt train --arch`)
    /// [default: the recommended recipe].
    #[arg(long, requires = "train", value_parser = design_names())]
    arch: Option<nprt_net::Design>,
    /// With --train: the minutes the X key adds to the run.
    #[arg(long, requires = "train", value_parser = crate::flags::finite_f64, default_value_t = 5.0)]
    extend_minutes: f64,
    /// Scene (default: the one the models were trained on); must be that scene.
    #[arg(long)]
    scene: Option<String>,
    /// Start the camera in this camera volume's JSON file instead of the scene's (its sidecar
    /// NAME.camera.json): the KITCHEN's is docs/kitchen.camera.json.
    #[arg(long)]
    camera_volume: Option<PathBuf>,
    /// Lightings M switches among, comma-separated: .exr/.hdr maps (e.g. a dataset's held-out
    /// maps) or built-in specs [default: with --train, the dataset's maps; else
    /// builtin:sky:30:250:3,builtin:sky:60:90:2,builtin:sky:12:200:6,builtin:indoor:9,builtin:indoor:3].
    #[arg(long, value_delimiter = ',')]
    maps: Vec<String>,
    /// Window size, N or WxH.
    #[arg(long, default_value = "384x288")]
    res: Resolution,
    /// Samples per pixel of the direct light, for models trained with `--direct traced`.
    #[arg(long, default_value_t = 4)]
    direct_spp: u32,
    /// Denoise that light with Open Image Denoise (O toggles it): auto (where OIDN is
    /// installed), on (an error without it; the flag alone means on) or off. A denoised frame
    /// is finished on the host.
    #[arg(long, default_value_t = nprt_render::Denoise::default(), num_args = 0..=1, default_missing_value = "on")]
    denoise_direct: nprt_render::Denoise,
    /// Exposure in stops (+ and - change it).
    #[arg(long, value_parser = crate::flags::finite_f32, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
    /// Degrees the map turns about +Y every frame (0: the view changes only with input).
    #[arg(long, value_parser = crate::flags::finite_f32, default_value_t = 0.0, allow_hyphen_values = true)]
    spin: f32,
    /// Start with the progressive path-traced reference of the view (R toggles it).
    #[arg(long)]
    reference: bool,
    /// Start with the text overlay hidden (H toggles it).
    #[arg(long)]
    no_overlay: bool,
    /// Folder of the screenshots the P (or F12) key writes, as nprt-view-NNNN.png.
    #[arg(long, default_value = ".")]
    screenshot_dir: PathBuf,
    /// Close after this many frames (for scripts and tests).
    #[arg(long)]
    frames: Option<usize>,
    /// With --frames: write the last frame, overlay included, to this PNG.
    #[arg(long, requires = "frames")]
    screenshot: Option<PathBuf>,
    /// Keys pressed at given times, comma-separated SECONDS:KEY, the seconds since the first
    /// frame and the key a character, or space, tab, escape or f12: e.g.
    /// 2:space,5:k,6:space,9:escape (for scripts and tests).
    #[arg(long, value_delimiter = ',', value_parser = parse_key)]
    keys: Vec<(f64, ScriptedKey)>,
    /// The networks' arithmetic: f32, or f16 (weights and activations in f16, sums in f32, on
    /// tensor cores where the adapter has them).
    #[arg(long, default_value = "f32")]
    precision: nprt_render::Precision,
    #[command(flatten)]
    device: DeviceArg,
}

/// A scripted key: SECONDS:KEY.
pub fn parse_key(s: &str) -> Result<(f64, ScriptedKey), String> {
    let (at, key) = s
        .split_once(':')
        .ok_or_else(|| format!("'{s}' is not SECONDS:KEY"))?;
    let at: f64 = (at.parse().ok())
        .filter(|t: &f64| (0.0..=1e6).contains(t))
        .ok_or_else(|| format!("'{at}' in '{s}' is not a time in seconds, 0 to 1,000,000"))?;
    let key = key.parse().map_err(|e| format!("{e} (in '{s}')"))?;
    Ok((at, key))
}

/// The run `--train` asks for: the recipe, or `--arch`'s design with its own defaults.
#[cfg(feature = "gpu")]
fn training(a: &ViewArgs) -> Result<Option<nprt_render::view::TrainingJob>> {
    let Some(data) = &a.train else {
        return Ok(None);
    };
    let asked = nprt_net::Asked {
        design: a.arch,
        ..Default::default()
    };
    let config = asked.config()?;
    nprt_net::check_minutes(a.extend_minutes, "--extend-minutes").map_err(anyhow::Error::msg)?;
    let minutes = a.minutes.unwrap_or(nprt_render::view::DEFAULT_MINUTES);
    let opts = nprt_net::TrainOptions {
        calibration: asked.calibration(),
        ..Default::default()
    }
    .with_run(config.design, nprt_net::RunLength::minutes(minutes), None);
    let out = a.out.clone().unwrap_or_else(|| {
        let mut name = data.file_name().unwrap_or_default().to_os_string();
        name.push("-model");
        data.with_file_name(name)
    });
    Ok(Some(nprt_render::view::TrainingJob {
        data: data.clone(),
        out,
        config,
        opts,
        asked,
        minutes: a.minutes,
        engine: a.device.engine()?,
    }))
}

#[cfg(feature = "gpu")]
pub fn run(a: ViewArgs) -> Result<()> {
    if let Some(path) = &a.screenshot {
        nprt_io::check_writable(path)?;
    }
    let training = training(&a)?;
    let maps = match (a.maps.is_empty(), &training) {
        (true, None) => DEFAULT_MAPS.map(String::from).to_vec(),
        _ => a.maps,
    };
    nprt_render::view::run_viewer(nprt_render::view::ViewerOptions {
        models: a.models,
        scene: a.scene,
        camera_volume: a.camera_volume,
        maps,
        resolution: a.res.0,
        engine: a.device.engine()?,
        direct_spp: a.direct_spp,
        denoise_direct: a.denoise_direct,
        exposure: a.exposure,
        spin_deg: a.spin,
        screenshot_dir: a.screenshot_dir,
        frames: a.frames,
        screenshot: a.screenshot,
        reference: a.reference,
        hide_overlay: a.no_overlay,
        precision: a.precision,
        training,
        extend_minutes: a.extend_minutes,
        keys: a.keys,
    })
}

/// `nprt bake --view`'s window: the bake's run trained as `nprt view --train` trains it,
/// `keys` pressed as `--keys` presses them.
#[cfg(feature = "gpu")]
pub fn training_window(keys: Vec<(f64, ScriptedKey)>) -> Result<nprt_paper::bake::TrainingWindow> {
    Ok(nprt_paper::bake::TrainingWindow(std::sync::Arc::new(
        move |r: &nprt_paper::bake::WindowedRun| {
            let job = nprt_render::view::TrainingJob {
                data: r.data.to_path_buf(),
                out: r.model.to_path_buf(),
                config: r.config.clone(),
                opts: r.opts.clone(),
                asked: nprt_net::Asked::default(),
                minutes: r.opts.schedule.minutes,
                engine: r.engine,
            };
            let mut opts = nprt_render::view::ViewerOptions::training(job);
            opts.keys = keys.clone();
            nprt_render::view::run_viewer(opts)
        },
    )))
}

#[cfg(not(feature = "gpu"))]
pub fn training_window(_: Vec<(f64, ScriptedKey)>) -> Result<nprt_paper::bake::TrainingWindow> {
    anyhow::bail!(
        "nprt bake --view: this nprt was built without the window; rebuild it with \
         `cargo build --release --features gpu` (docs/building.md)"
    )
}

#[cfg(not(feature = "gpu"))]
pub fn run(_: ViewArgs) -> Result<()> {
    anyhow::bail!(
        "nprt view: this nprt was built without the window and GPU frame path; rebuild it with \
         `cargo build --release --features gpu` (docs/building.md)"
    )
}
