//! `generate` as one call: from options, whose defaults are stated here and nowhere else, to a
//! dataset folder (load the scene, choose the camera volume and maps, plan, render the shard).

use std::path::PathBuf;

use anyhow::Result;
use nprt_scene::load_scene;
use nprt_trace::{TraceDevice, TraceScene, Tracer};

use crate::camera_choice::CameraChoice;
use crate::dataset::{self, Manifest, Request, Summary, TransferBasis, ViewSpec};
use crate::lighting;

/// What to render and where; `Default`'s views are [`ViewSpec`]'s.
#[derive(Clone, Debug)]
pub struct GenerateOptions {
    /// `builtin:room`, or a Mitsuba .xml / glTF / mesh file.
    pub scene: String,
    /// A folder of lat-long maps, or `builtin` (a fresh procedural lighting for every view).
    pub envmaps: String,
    pub out: PathBuf,
    pub views: ViewSpec,
    /// Record the training pixels' transfer vectors on this basis (CPU tracer only).
    pub transfer: Option<TransferBasis>,
    /// Maps of a folder held out for testing (default: a fifth, at least one).
    pub test_maps: Option<usize>,
    /// With a folder of maps, the share of training views lit by a procedural lighting of
    /// their own (default [`lighting::DEFAULT_MIX_BUILTIN`]); not for `builtin`.
    pub mix_builtin: Option<f32>,
    pub camera: CameraChoice,
    /// Render only views with index ≡ K (mod N).
    pub shard: (u64, u64),
    /// Where the views are path traced: the CPU, or the same tracer on the GPU (the one that
    /// began a dataset is recorded in its manifest; either resumes it).
    pub device: TraceDevice,
    pub progress: bool,
}

impl Default for GenerateOptions {
    fn default() -> Self {
        GenerateOptions {
            scene: "builtin:room".into(),
            envmaps: "builtin".into(),
            out: PathBuf::from("dataset"),
            views: ViewSpec::default(),
            transfer: None,
            test_maps: None,
            mix_builtin: None,
            camera: CameraChoice::default(),
            shard: (0, 1),
            device: TraceDevice::Cpu,
            progress: true,
        }
    }
}

/// What was planned before rendering began: the manifest, and warnings owed to the user.
pub struct Planned<'a> {
    pub manifest: &'a Manifest,
    pub warnings: Vec<String>,
}

/// Memory a planned view holds for the whole run: its record and manifest line, and with
/// built-in lighting its own procedural map (256×128 texels and their sampling distribution).
const BYTES_PER_VIEW: u128 = 1 << 10;
const BYTES_PER_BUILTIN_MAP: u128 = 1 << 20;

/// Refuses view counts and resolutions this machine's memory cannot hold, before anything is
/// allocated (`--train-views 1000000000000` grew until killed).
fn check_sizes(opts: &GenerateOptions, builtin_share: f32) -> Result<()> {
    let views = opts.views.train_views as u128 + opts.views.test_views as u128;
    let own_maps = if opts.envmaps == "builtin" {
        views
    } else {
        (opts.views.train_views as f64 * builtin_share.clamp(0.0, 1.0) as f64) as u128
    };
    nprt_io::ensure_memory(
        views * BYTES_PER_VIEW + own_maps * BYTES_PER_BUILTIN_MAP,
        &format!("planning {views} views"),
    )?;
    if let Some(basis) = opts.transfer {
        if !opts.device.is_cpu() {
            anyhow::bail!(
                "--transfer {basis}: transfer vectors are recorded by the CPU tracer only; \
                 generate with --device cpu"
            );
        }
        // A training view's transfer as traced (a vector per pixel) and as written.
        let [w, h] = opts.views.train_resolution;
        let floats = 2 * basis.floats() as u128;
        nprt_io::ensure_memory(
            w as u128 * h as u128 * floats * 4 * 3,
            &format!("the transfer vectors ({basis}) of a {w}×{h} training view"),
        )?;
    }
    for (split, [w, h]) in [
        ("training", opts.views.train_resolution),
        ("test", opts.views.test_resolution),
    ] {
        opts.device
            .check_frame(w, h, &format!("a {w}×{h} {split} view"))?;
    }
    Ok(())
}

impl GenerateOptions {
    /// The share of views lit by built-in maps: `--mix-builtin`, else none under `builtin`
    /// alone and the default mix beside a folder of maps.
    fn builtin_share(&self) -> f32 {
        match (self.envmaps.as_str(), self.mix_builtin) {
            (_, Some(share)) => share,
            ("builtin", None) => 0.0,
            (_, None) => lighting::DEFAULT_MIX_BUILTIN,
        }
    }

    /// The maps and each view's lighting: refuses maps that cannot be listed and held-out
    /// maps that cannot be held out, before any work (a caller that makes folders of its own
    /// asks first).
    pub fn lighting(&self) -> Result<(Vec<String>, dataset::MapAssignment)> {
        lighting::choose(
            &self.envmaps,
            self.views.train_views,
            self.views.test_views,
            self.test_maps,
            self.builtin_share(),
            self.views.seed,
        )
    }
}

/// Plans the dataset (nothing is written before the plan holds), calls `planned` with it, then
/// renders this shard's missing views.
pub fn generate(opts: &GenerateOptions, planned: impl FnOnce(Planned)) -> Result<Summary> {
    check_sizes(opts, opts.builtin_share())?;
    dataset::check_not_model_folder(&opts.out)?;
    let scene = load_scene(&opts.scene, &dataset::relit())?;
    let volume = opts.camera.resolve(&scene, &opts.scene)?;
    let (specs, assignment) = opts.lighting()?;
    let maps = lighting::load_all(&specs)?;
    let warnings = scene
        .warnings
        .iter()
        .cloned()
        .chain(maps.iter().flat_map(|m| m.warnings()))
        .collect();
    let request = Request {
        scene_spec: opts.scene.clone(),
        scene: &scene,
        scene_source: dataset::scene_source(&opts.scene)?,
        volume,
        lighting: assignment,
        map_specs: specs,
        maps,
        views: opts.views,
    };
    let ts = TraceScene::new(&scene);
    let mut manifest = dataset::plan(&request, &ts)?;
    manifest.settings.tracer = opts.device;
    manifest.settings.transfer = opts.transfer;
    // Opened before the folder is made: a GPU that does not open leaves nothing behind.
    let tracer = Tracer::new(opts.device, &ts)?;
    dataset::prepare(&opts.out, &manifest)?;
    planned(Planned {
        manifest: &manifest,
        warnings,
    });
    dataset::run(
        &tracer,
        &request.maps,
        &manifest,
        &opts.out,
        opts.shard,
        opts.progress,
    )
}
