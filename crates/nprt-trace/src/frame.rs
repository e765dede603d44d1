//! What one render produces per pixel, and how it is stored as named EXR channels.
//!
//! Channels: `R,G,B` radiance; `direct.R/G/B` direct-lighting radiance (emitter seen directly
//! plus one bounce); `position.X/Y/Z` world-space first hit; `normal.X/Y/Z` shading normal
//! facing the viewer; `view.X/Y/Z` unit direction from the hit towards the camera (ωo);
//! `kd.R/G/B`, `ks.R/G/B`; `alpha` (GGX α); `mask` (1 where the pixel-centre ray hits geometry).
//! G-buffer layers are those of the ray through the pixel centre; background pixels hold zeros.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{bail, Context, Result};
use glam::Vec3;
use nprt_scene::envmap::MAX_RADIANCE;

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

    /// Pixel `i`.
    pub fn sample(&self, i: usize) -> GSample {
        GSample {
            position: self.position[i],
            normal: self.normal[i],
            view: self.view[i],
            kd: self.kd[i],
            ks: self.ks[i],
            alpha: self.alpha[i],
            mask: self.mask[i],
        }
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

const RGB: [&str; 3] = ["R", "G", "B"];
const XYZ: [&str; 3] = ["X", "Y", "Z"];

/// The three-component layers in file order: (channel prefix, component names).
const VECTOR_LAYERS: [(&str, [&str; 3]); 7] = [
    ("", RGB),
    ("direct", RGB),
    ("position", XYZ),
    ("normal", XYZ),
    ("view", XYZ),
    ("kd", RGB),
    ("ks", RGB),
];

fn channel_name(prefix: &str, component: &str) -> String {
    if prefix.is_empty() {
        component.to_string()
    } else {
        format!("{prefix}.{component}")
    }
}

impl Frame {
    fn vector_layers(&self) -> [&Vec<Vec3>; 7] {
        let g = &self.gbuffer;
        [
            &self.radiance,
            &self.direct,
            &g.position,
            &g.normal,
            &g.view,
            &g.kd,
            &g.ks,
        ]
    }

    /// Every layer as (channel name, data), in the order documented above.
    pub fn channels(&self) -> Vec<(String, Vec<f32>)> {
        let mut out: Vec<(String, Vec<f32>)> = VECTOR_LAYERS
            .iter()
            .zip(self.vector_layers())
            .flat_map(|((p, names), data)| {
                (0..3).map(move |k| {
                    (
                        channel_name(p, names[k]),
                        data.iter().map(|v| v[k]).collect(),
                    )
                })
            })
            .collect();
        out.push(("alpha".into(), self.gbuffer.alpha.clone()));
        out.push(("mask".into(), self.gbuffer.mask.clone()));
        out
    }

    /// Memory that making a frame holds per pixel: its layers (92 bytes), the sample
    /// accumulators, a relit frame's network inputs, and the copies a file is written from.
    pub const BYTES_PER_PIXEL: u128 = 512;

    /// Refuses a `width × height` frame (`what`: "a 100000×100000 frame") that this machine's
    /// memory cannot hold, before anything is allocated.
    pub fn check_size(width: u32, height: u32, what: &str) -> Result<()> {
        nprt_io::ensure_memory(width as u128 * height as u128 * Self::BYTES_PER_PIXEL, what)
    }

    /// The values a channel may hold, where it has a range (others: any finite value):
    /// radiance and direct light within [0, [`MAX_RADIANCE`]], the largest a map may hold (a
    /// dataset's writer holds them there), and reflectances, α and the mask within [0, 1], as
    /// the G-buffer records them.
    pub fn channel_range(name: &str) -> Option<(f32, f32)> {
        match name.split_once('.') {
            Some(("kd" | "ks", _)) => Some((0.0, 1.0)),
            Some(("direct", _)) => Some((0.0, MAX_RADIANCE)),
            Some(_) => None,
            None if RGB.contains(&name) => Some((0.0, MAX_RADIANCE)),
            None if ["alpha", "mask"].contains(&name) => Some((0.0, 1.0)),
            None => None,
        }
    }

    /// The frame held by named channels (as [`nprt_io::exr::read_channels`] returns them),
    /// refusing a missing or wrongly sized channel, non-finite values, radiance outside [0,
    /// [`MAX_RADIANCE`]], and reflectances, α or mask outside [0, 1] (the G-buffer's range),
    /// naming the pixel.
    pub fn from_channels(
        width: usize,
        height: usize,
        ch: &HashMap<String, Vec<f32>>,
    ) -> Result<Frame> {
        // A value past its channel's range is a damaged or edited file, named here rather than
        // blamed on --lr by a training.
        let get = |name: &str| -> Result<&Vec<f32>> {
            let data = ch
                .get(name)
                .with_context(|| format!("lacks channel '{name}'"))?;
            if data.len() != width * height {
                bail!(
                    "channel '{name}' has {} values for {width}×{height} pixels",
                    data.len()
                );
            }
            let (lo, hi) = Self::channel_range(name).unwrap_or((f32::MIN, f32::MAX));
            if let Some(i) = data
                .iter()
                .position(|v| !v.is_finite() || *v < lo || *v > hi)
            {
                let why = match (data[i].is_finite(), data[i] < 0.0 && lo == 0.0) {
                    (false, _) => String::new(),
                    (true, true) => ", but cannot be negative".into(),
                    // 1e12 rather than its 13 digits; 1 as 1.
                    (true, false) if hi >= 1e6 => format!(", outside [{lo}, {hi:e}]"),
                    (true, false) => format!(", outside [{lo}, {hi}]"),
                };
                bail!(
                    "channel '{name}' is {} at pixel ({}, {}){why}",
                    data[i],
                    i % width,
                    i / width,
                );
            }
            Ok(data)
        };
        let mut layers = Vec::with_capacity(VECTOR_LAYERS.len());
        for (prefix, names) in VECTOR_LAYERS {
            let c = [
                get(&channel_name(prefix, names[0]))?,
                get(&channel_name(prefix, names[1]))?,
                get(&channel_name(prefix, names[2]))?,
            ];
            layers.push(
                (0..width * height)
                    .map(|i| Vec3::new(c[0][i], c[1][i], c[2][i]))
                    .collect::<Vec<_>>(),
            );
        }
        let [radiance, direct, position, normal, view, kd, ks]: [Vec<Vec3>; 7] =
            layers.try_into().expect("one entry per vector layer");
        Ok(Frame {
            width,
            height,
            radiance,
            direct,
            gbuffer: GBuffer {
                position,
                normal,
                view,
                kd,
                ks,
                alpha: get("alpha")?.clone(),
                mask: get("mask")?.clone(),
            },
        })
    }

    pub fn write_exr(&self, path: &Path) -> Result<()> {
        nprt_io::exr::write_channels(path, self.width, self.height, &self.channels())
    }

    /// Mean radiance over all pixels.
    pub fn mean(&self) -> Vec3 {
        self.radiance.iter().copied().sum::<Vec3>() / self.radiance.len() as f32
    }
}
