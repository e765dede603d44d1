//! The model's frame of a held-out test view beside that view's path-traced reference, as
//! run time makes it (traced direct light, denoised where OIDN is installed): what a bake
//! shows of its model, as preview.png while it trains and comparison.png at its end.

use std::path::Path;

use anyhow::{Context, Result};
use glam::Vec3;
use nprt_data::dataset::{load_checked_scene, load_manifest};
use nprt_data::views::load_view;
use nprt_net::training::training_set::open_recorded_map;
use nprt_net::Engine;
use nprt_render::{Denoise, DirectSampling, Relighter, DEFAULT_DIRECT_SPP};
use nprt_trace::{render_gbuffer, TraceScene};

/// Columns of black between the two frames.
const GAP: usize = 4;

/// Writes `out` (PNG): the model in `model`'s frame of the dataset `data`'s first test view,
/// then a gap, then that view's reference, both at the reference's exposure.
pub fn write_comparison(model: &Path, data: &Path, engine: Engine, out: &Path) -> Result<()> {
    let manifest = load_manifest(data)?;
    let record = (manifest.views.iter())
        .find(|v| v.split == "test")
        .with_context(|| format!("dataset '{}' has no test view", data.display()))?;
    let view = load_view(data, &manifest, record)?;
    let s = &manifest.settings;
    let what = format!("dataset '{}' was rendered from", data.display());
    let scene = load_checked_scene(&s.scene, &s.scene_hash, &what)?;
    let ts = TraceScene::new(&scene);
    let r = Relighter::load(model, engine)?;
    let map = open_recorded_map(&manifest, record.map)?;
    let g = render_gbuffer(&ts, &view.camera);
    let (mut rgb, _) = r.shade(&g, (&map, record.rotation_deg))?;
    let sampling = DirectSampling {
        spp: DEFAULT_DIRECT_SPP,
        seed: record.seed,
        denoiser: Denoise::default().denoiser(&r, model)?,
    };
    let placed = map.rotated_y(record.rotation_deg);
    r.complete(&ts, &view.camera, &placed, &g, sampling, &mut rgb)?;
    let (w, h) = (view.width, view.height);
    let exposure = nprt_eval::auto_exposure(&view.radiance, &view.gbuffer.mask);
    let side = 2 * w + GAP;
    let mut both = vec![Vec3::ZERO; side * h];
    for y in 0..h {
        let row = &mut both[y * side..(y + 1) * side];
        row[..w].copy_from_slice(&rgb[y * w..(y + 1) * w]);
        row[w + GAP..].copy_from_slice(&view.radiance[y * w..(y + 1) * w]);
    }
    nprt_io::write_png(&both, side, h, exposure, out)
}
