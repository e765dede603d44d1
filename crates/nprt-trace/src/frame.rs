//! What one render produces per pixel, and how it is stored as named EXR channels.
//!
//! Channels: `R,G,B` radiance; `direct.R/G/B` direct-lighting radiance (emitter seen directly
//! plus one bounce); `position.X/Y/Z` world-space first hit; `normal.X/Y/Z` shading normal
//! facing the viewer; `view.X/Y/Z` unit direction from the hit towards the camera (ωo);
//! `kd.R/G/B`, `ks.R/G/B`; `alpha` (GGX α); `mask` (1 where the pixel-centre ray hits geometry).
//! G-buffer layers are those of the ray through the pixel centre; background pixels hold zeros.

use std::path::Path;

use anyhow::Result;
use glam::Vec3;

#[derive(Clone, Debug, Default)]
pub struct GBuffer {
    pub position: Vec<Vec3>,
    pub normal: Vec<Vec3>,
    pub view: Vec<Vec3>,
    pub kd: Vec<Vec3>,
    pub ks: Vec<Vec3>,
    pub alpha: Vec<f32>,
    pub mask: Vec<f32>,
}

/// The G-buffer of one pixel; all zeros where the centre ray sees the background.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GSample {
    pub position: Vec3,
    pub normal: Vec3,
    pub view: Vec3,
    pub kd: Vec3,
    pub ks: Vec3,
    pub alpha: f32,
    pub mask: f32,
}

impl GBuffer {
    pub fn push(&mut self, s: GSample) {
        self.position.push(s.position);
        self.normal.push(s.normal);
        self.view.push(s.view);
        self.kd.push(s.kd);
        self.ks.push(s.ks);
        self.alpha.push(s.alpha);
        self.mask.push(s.mask);
    }
}

#[derive(Clone, Debug)]
pub struct Frame {
    pub width: usize,
    pub height: usize,
    pub radiance: Vec<Vec3>,
    pub direct: Vec<Vec3>,
    pub gbuffer: GBuffer,
}

fn split(prefix: &str, names: [&str; 3], data: &[Vec3]) -> Vec<(String, Vec<f32>)> {
    (0..3)
        .map(|k| {
            let name = if prefix.is_empty() {
                names[k].to_string()
            } else {
                format!("{prefix}.{}", names[k])
            };
            (name, data.iter().map(|v| v[k]).collect())
        })
        .collect()
}

impl Frame {
    /// Every layer as (channel name, data), in the order documented above.
    pub fn channels(&self) -> Vec<(String, Vec<f32>)> {
        const RGB: [&str; 3] = ["R", "G", "B"];
        const XYZ: [&str; 3] = ["X", "Y", "Z"];
        let g = &self.gbuffer;
        let mut out = split("", RGB, &self.radiance);
        out.extend(split("direct", RGB, &self.direct));
        out.extend(split("position", XYZ, &g.position));
        out.extend(split("normal", XYZ, &g.normal));
        out.extend(split("view", XYZ, &g.view));
        out.extend(split("kd", RGB, &g.kd));
        out.extend(split("ks", RGB, &g.ks));
        out.push(("alpha".into(), g.alpha.clone()));
        out.push(("mask".into(), g.mask.clone()));
        out
    }

    pub fn write_exr(&self, path: &Path) -> Result<()> {
        crate::exr_io::write_channels(path, self.width, self.height, &self.channels())
    }

    /// Mean radiance over all pixels.
    pub fn mean(&self) -> Vec3 {
        self.radiance.iter().copied().sum::<Vec3>() / self.radiance.len() as f32
    }
}
