//! Lighting over time: a sequence of environment maps, each held for a share of the frames
//! while it turns about +Y.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{bail, Context, Result};
use nprt_scene::open_envmap;
use nprt_scene::EnvMap;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// A map file or a built-in spec (`builtin:sky:ELEV:AZIM:TURB`, `builtin:indoor:SEED`).
    pub map: String,
    /// Relative length of the segment (frames are shared out in proportion).
    #[serde(default = "one")]
    pub weight: f32,
    /// Rotation about +Y at the segment's start and end, degrees.
    #[serde(default)]
    pub rotation_deg: [f32; 2],
}

fn one() -> f32 {
    1.0
}

/// The maps of a schedule, opened, and which one lights each frame at what rotation.
pub struct LightingSchedule {
    pub segments: Vec<Segment>,
    pub maps: Vec<EnvMap>,
}

/// Parses and checks a lighting schedule's JSON:
/// `{"segments": [{"map": …, "weight": 1, "rotation_deg": [0, 90]}]}`.
pub fn parse_segments(text: &str) -> Result<Vec<Segment>> {
    #[derive(Deserialize)]
    struct File {
        segments: Vec<Segment>,
    }
    let segments = serde_json::from_str::<File>(text)
        .context(
            "is not {\"segments\": [{\"map\": …, \"weight\": w, \"rotation_deg\": [from, to]}]}",
        )?
        .segments;
    check_segments(&segments)?;
    Ok(segments)
}

fn check_segments(segments: &[Segment]) -> Result<()> {
    if segments.is_empty() {
        bail!("names no map");
    }
    for s in segments {
        if !(s.weight > 0.0 && s.weight.is_finite()) {
            bail!("segment '{}' has weight {}, must be > 0", s.map, s.weight);
        }
        if !s.rotation_deg.iter().all(|r| r.is_finite()) {
            bail!("segment '{}' has a non-finite rotation", s.map);
        }
    }
    if !segments.iter().map(|s| s.weight).sum::<f32>().is_finite() {
        bail!("the segments' weights add up to more than a 32-bit float holds");
    }
    Ok(())
}

/// The segment index and rotation (degrees) lighting frame `i` of `frames` under `segments`
/// (checked by [`parse_segments`]): frames are shared out in proportion to the weights.
pub fn segment_at(segments: &[Segment], i: usize, frames: usize) -> (usize, f32) {
    let total: f32 = segments.iter().map(|s| s.weight).sum();
    let t = if frames > 1 {
        i as f32 / (frames - 1) as f32
    } else {
        0.0
    } * total;
    let mut start = 0.0;
    for (k, s) in segments.iter().enumerate() {
        let end = start + s.weight;
        if t < end || k + 1 == segments.len() {
            let f = ((t - start) / s.weight).clamp(0.0, 1.0);
            let [a, b] = s.rotation_deg;
            return (k, a + (b - a) * f);
        }
        start = end;
    }
    (0, 0.0)
}

impl LightingSchedule {
    /// `spec` is a JSON file (see [`parse_segments`]) or a comma-separated list of maps, each
    /// turning by `spin_deg` over its segment.
    pub fn parse(spec: &str, spin_deg: f32) -> Result<Self> {
        let segments = if spec.ends_with(".json") {
            let text = nprt_io::read_input_string(Path::new(spec))
                .with_context(|| format!("cannot read lighting schedule '{spec}'"))?;
            parse_segments(&text).with_context(|| format!("lighting schedule '{spec}'"))?
        } else {
            let segments: Vec<Segment> = spec
                .split(',')
                .filter(|s| !s.trim().is_empty())
                .map(|m| Segment {
                    map: m.trim().to_string(),
                    weight: 1.0,
                    rotation_deg: [0.0, spin_deg],
                })
                .collect();
            check_segments(&segments).with_context(|| format!("lighting schedule '{spec}'"))?;
            segments
        };
        // Each distinct map is opened once and shared by its segments (a map is an Arc):
        // opened per segment, 10⁴ segments of one map grew to 7 GB. The distinct maps' texels
        // are checked against the available memory as they come.
        let mut opened: HashMap<&str, EnvMap> = HashMap::new();
        let mut bytes = 0u128;
        let mut maps = Vec::with_capacity(segments.len());
        for s in &segments {
            if !opened.contains_key(s.map.as_str()) {
                let map = open_envmap(&s.map)?;
                // Texels and the sampling distribution's tables, about 24 bytes a texel.
                bytes += 24 * (map.width() * map.height()) as u128;
                nprt_io::ensure_memory(bytes, "the lighting schedule's maps")?;
                opened.insert(&s.map, map);
            }
            maps.push(opened[s.map.as_str()].clone());
        }
        Ok(LightingSchedule { segments, maps })
    }

    /// The map index and rotation lighting frame `i` of `frames`.
    pub fn at(&self, i: usize, frames: usize) -> (usize, f32) {
        segment_at(&self.segments, i, frames)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_share_segments() {
        let s = LightingSchedule::parse("builtin:indoor:1,builtin:indoor:2", 90.0).unwrap();
        assert_eq!(s.at(0, 11), (0, 0.0));
        assert_eq!(s.at(10, 11), (1, 90.0));
        let (k, r) = s.at(2, 11);
        assert_eq!(k, 0);
        assert!((r - 36.0).abs() < 1e-3);
        assert!(LightingSchedule::parse("builtin:moon", 0.0).is_err());
        assert!(LightingSchedule::parse(" , ", 0.0).is_err());
    }
}
