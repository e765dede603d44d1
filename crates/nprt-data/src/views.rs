//! Dataset views as whole images: reference radiance, its direct part, and the G-buffer, read
//! and checked against the manifest (for training and evaluation alike).

use std::path::Path;

use crate::dataset::{read_view, Manifest, Transfer, ViewRecord};
use anyhow::{Context, Result};
use glam::Vec3;
use nprt_scene::Camera;
use nprt_trace::GBuffer;
use rayon::prelude::*;

pub struct ImageView {
    pub record: ViewRecord,
    pub camera: Camera,
    pub width: usize,
    pub height: usize,
    pub radiance: Vec<Vec3>,
    pub direct: Vec<Vec3>,
    pub gbuffer: GBuffer,
    /// Radiance of the first half of the samples, for a test view rendered in halves.
    pub half: Option<Vec<Vec3>>,
    /// Transfer vectors, for a training view of a dataset made with `--transfer`.
    pub transfer: Option<Transfer>,
}

impl ImageView {
    pub fn foreground(&self) -> usize {
        self.gbuffer.mask.iter().filter(|&&m| m > 0.5).count()
    }
}

/// Reads the views of `split` ("train" or "test") of the dataset in `dir`, in parallel.
pub fn load_views(dir: &Path, manifest: &Manifest, split: &str) -> Result<Vec<ImageView>> {
    manifest
        .views
        .par_iter()
        .filter(|v| v.split == split)
        .map(|v| load_view(dir, manifest, v))
        .collect()
}

/// Reads one view, refusing a file whose channels or size disagree with the manifest.
pub fn load_view(dir: &Path, manifest: &Manifest, view: &ViewRecord) -> Result<ImageView> {
    let path = dir.join(&view.file);
    let image = read_view(&path, view, manifest.settings.parts(view)).with_context(|| {
        format!(
            "dataset view '{}' is unusable (run `nprt generate` again to redo it)",
            path.display()
        )
    })?;
    let frame = image.frame;
    Ok(ImageView {
        record: view.clone(),
        camera: view.camera(),
        width: frame.width,
        height: frame.height,
        radiance: frame.radiance,
        direct: frame.direct,
        gbuffer: frame.gbuffer,
        half: image.half,
        transfer: image.transfer,
    })
}
