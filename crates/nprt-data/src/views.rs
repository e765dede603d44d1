//! Dataset views as whole images: reference radiance, its direct part, and the G-buffer, read
//! and checked against the manifest (for training and evaluation alike).

use std::path::Path;

use crate::dataset::{check_channels, Manifest, ViewRecord};
use anyhow::{Context, Result};
use glam::Vec3;
use nprt_scene::Camera;
use nprt_trace::exr_io::read_channels;
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
        .map(|v| load_view(dir, v))
        .collect()
}

/// Reads one view, refusing a file whose channels or size disagree with the manifest.
pub fn load_view(dir: &Path, view: &ViewRecord) -> Result<ImageView> {
    let path = dir.join(&view.file);
    let (w, h, ch) = read_channels(&path)?;
    check_channels(w, h, &ch, view).with_context(|| {
        format!(
            "dataset view '{}' is unusable (run `nprt generate` again to redo it)",
            path.display()
        )
    })?;
    let vec3 = |prefix: &str, names: [&str; 3]| -> Vec<Vec3> {
        let c = names.map(|n| {
            let key = if prefix.is_empty() {
                n.to_string()
            } else {
                format!("{prefix}.{n}")
            };
            &ch[&key]
        });
        (0..w * h)
            .map(|i| Vec3::new(c[0][i], c[1][i], c[2][i]))
            .collect()
    };
    const RGB: [&str; 3] = ["R", "G", "B"];
    const XYZ: [&str; 3] = ["X", "Y", "Z"];
    Ok(ImageView {
        record: view.clone(),
        camera: view.camera(),
        width: w,
        height: h,
        radiance: vec3("", RGB),
        direct: vec3("direct", RGB),
        gbuffer: GBuffer {
            position: vec3("position", XYZ),
            normal: vec3("normal", XYZ),
            view: vec3("view", XYZ),
            kd: vec3("kd", RGB),
            ks: vec3("ks", RGB),
            alpha: ch["alpha"].clone(),
            mask: ch["mask"].clone(),
        },
    })
}
