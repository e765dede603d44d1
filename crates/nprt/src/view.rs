//! `nprt view`: flags for the interactive viewer; the window is `nprt_render::view`.

use std::path::PathBuf;

use anyhow::Result;

use crate::flags::{DeviceArg, Resolution};

#[derive(clap::Args)]
pub struct ViewArgs {
    /// Trained model folders of one scene (from `nprt train`); Tab switches among them.
    #[arg(required = true)]
    models: Vec<PathBuf>,
    /// Scene (default: the one the models were trained on); must be that scene.
    #[arg(long)]
    scene: Option<String>,
    /// Start the camera in this camera volume's JSON file instead of the scene's (its sidecar
    /// NAME.camera.json): the KITCHEN's is docs/kitchen.camera.json.
    #[arg(long)]
    camera_volume: Option<PathBuf>,
    /// Lightings M switches among, comma-separated: .exr/.hdr maps (e.g. a dataset's held-out
    /// maps) or built-in specs.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "builtin:sky:30:250:3,builtin:sky:60:90:2,builtin:sky:12:200:6,builtin:indoor:9,builtin:indoor:3"
    )]
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
    /// The networks' arithmetic: f32, or f16 (weights and activations in f16, sums in f32, on
    /// tensor cores where the adapter has them).
    #[arg(long, default_value = "f32")]
    precision: nprt_render::Precision,
    #[command(flatten)]
    device: DeviceArg,
}

#[cfg(feature = "gpu")]
pub fn run(a: ViewArgs) -> Result<()> {
    if let Some(path) = &a.screenshot {
        nprt_io::check_writable(path)?;
    }
    nprt_render::view::run_viewer(nprt_render::view::ViewerOptions {
        models: a.models,
        scene: a.scene,
        camera_volume: a.camera_volume,
        maps: a.maps,
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
    })
}

#[cfg(not(feature = "gpu"))]
pub fn run(_: ViewArgs) -> Result<()> {
    anyhow::bail!(
        "nprt view: this nprt was built without the window and GPU frame path; rebuild it with \
         `cargo build --release --features gpu` (docs/building.md)"
    )
}
