//! Camera paths: keyframes (position, target, field of view) interpolated over time, from a JSON
//! file or derived from a scene's camera volume.

use std::path::Path;

use anyhow::{bail, Context, Result};
use glam::Vec3;
use nprt_scene::{Camera, CameraVolume, MAX_COORDINATE};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Keyframe {
    pub position: [f32; 3],
    pub target: [f32; 3],
    /// Horizontal field of view, degrees.
    #[serde(default = "default_fov")]
    pub fov_x_deg: f32,
}

fn default_fov() -> f32 {
    60.0
}

/// A camera path: keyframes evenly spaced in time, joined by Catmull-Rom splines (smooth
/// through every keyframe); the path does not loop unless its last keyframe repeats the first.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraPath {
    pub keyframes: Vec<Keyframe>,
}

fn catmull_rom(p: [Vec3; 4], t: f32) -> Vec3 {
    let (t2, t3) = (t * t, t * t * t);
    0.5 * ((2.0 * p[1])
        + (p[2] - p[0]) * t
        + (2.0 * p[0] - 5.0 * p[1] + 4.0 * p[2] - p[3]) * t2
        + (3.0 * p[1] - p[0] - 3.0 * p[2] + p[3]) * t3)
}

impl CameraPath {
    /// Reads `{"keyframes": [{"position": [x,y,z], "target": [x,y,z], "fov_x_deg": 60}, …]}`.
    pub fn load(path: &Path) -> Result<Self> {
        let text = nprt_io::read_input_string(path)
            .with_context(|| format!("cannot read camera path '{}'", path.display()))?;
        Self::from_json(&text).with_context(|| format!("camera path '{}'", path.display()))
    }

    /// Parses and checks a camera path's JSON.
    pub fn from_json(text: &str) -> Result<Self> {
        let p: CameraPath = serde_json::from_str(text).context(
            "is not {\"keyframes\": [{\"position\": [x,y,z], \"target\": [x,y,z], \"fov_x_deg\": deg}, …]}",
        )?;
        p.check()?;
        Ok(p)
    }

    fn check(&self) -> Result<()> {
        if self.keyframes.is_empty() {
            bail!("has no keyframes");
        }
        for (i, k) in self.keyframes.iter().enumerate() {
            let finite = k.position.iter().chain(&k.target).all(|v| v.is_finite());
            if !finite || Vec3::from(k.position) == Vec3::from(k.target) {
                bail!("keyframe {i} has a non-finite value or looks at its own position");
            }
            // Checked before any frame is written: at 3e38 the rays' arithmetic overflows and
            // the first frame was written before the NaN radiance stopped the run.
            if k.position
                .iter()
                .chain(&k.target)
                .any(|v| v.abs() > MAX_COORDINATE)
            {
                bail!(
                    "keyframe {i} lies beyond ±{MAX_COORDINATE:e} scene units, the farthest a \
                     scene or camera may reach (position {:?}, target {:?})",
                    k.position,
                    k.target
                );
            }
            if !(1.0..179.0).contains(&k.fov_x_deg) {
                bail!(
                    "keyframe {i} has a field of view of {}°, outside 1–179°",
                    k.fov_x_deg
                );
            }
        }
        Ok(())
    }

    /// [`Self::through_volume`] of the camera volume in the JSON file `file`, or else of
    /// `scene`'s own (its sidecar NAME.camera.json); where there is neither, an error that
    /// names the scene `spec` and ends with `hint`.
    pub fn through_volume_of(
        file: Option<&Path>,
        scene: &nprt_scene::Scene,
        spec: &str,
        hint: &str,
    ) -> Result<Self> {
        Ok(Self::through_volume(&match file {
            Some(f) => CameraVolume::load(f)?,
            None => scene.camera_volume.clone().with_context(|| {
                format!("scene '{spec}' has no camera volume (no sidecar NAME.camera.json); {hint}")
            })?,
        }))
    }

    /// A slow sweep through a scene's camera volume: across the volume and back, panning
    /// within the volume's spread of view directions.
    pub fn through_volume(v: &CameraVolume) -> Self {
        let look = v.look.normalize();
        let side = look.cross(Vec3::Y).normalize_or(Vec3::X);
        let centre = (v.min + v.max) * 0.5;
        let half = (v.max - v.min) * 0.5;
        let reach = half.max_element().max(1e-3) * 4.0;
        let pan = v.spread_deg.to_radians().tan() * 0.6;
        let keyframes = [
            (-0.8, 0.3, -1.0),
            (0.0, -0.3, 0.0),
            (0.8, 0.3, 1.0),
            (0.0, 0.6, 0.0),
        ]
        .iter()
        .chain(std::iter::once(&(-0.8, 0.3, -1.0)))
        .map(|&(a, b, turn): &(f32, f32, f32)| {
            let position = centre + half * (side * a + Vec3::Y * b * 0.5 + look * b * 0.5);
            let dir = (look + side * (pan * -turn)).normalize();
            Keyframe {
                position: position.to_array(),
                target: (position + dir * reach).to_array(),
                fov_x_deg: v.fov_deg,
            }
        })
        .collect();
        CameraPath { keyframes }
    }

    /// The camera at time `t` ∈ [0, 1].
    pub fn camera(&self, t: f32, width: u32, height: u32) -> Camera {
        let k = &self.keyframes;
        let n = k.len();
        let (pos, target, fov) = if n == 1 {
            (
                Vec3::from(k[0].position),
                Vec3::from(k[0].target),
                k[0].fov_x_deg,
            )
        } else {
            let x = t.clamp(0.0, 1.0) * (n - 1) as f32;
            let i = (x.floor() as usize).min(n - 2);
            let f = x - i as f32;
            let at = |j: isize| &k[j.clamp(0, n as isize - 1) as usize];
            let ids = [i as isize - 1, i as isize, i as isize + 1, i as isize + 2];
            let pick = |g: fn(&Keyframe) -> [f32; 3]| ids.map(|j| Vec3::from(g(at(j))));
            (
                catmull_rom(pick(|k| k.position), f),
                catmull_rom(pick(|k| k.target), f),
                at(i as isize).fov_x_deg * (1.0 - f) + at(i as isize + 1).fov_x_deg * f,
            )
        };
        Camera::look_at(pos, target, Vec3::Y, fov, width, height)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A keyframe beyond the scene's reach is refused when the path is read, before any
    /// frame; one at the limit is kept.
    #[test]
    fn keyframes_beyond_the_scenes_reach_are_refused_when_read() {
        let path = |x: f32| {
            format!(
                r#"{{"keyframes": [{{"position": [0, 0, 0], "target": [0, 0, -1]}},
                    {{"position": [{x:e}, 1, 0], "target": [0, 0, -1]}}]}}"#
            )
        };
        assert!(CameraPath::from_json(&path(MAX_COORDINATE)).is_ok());
        for x in [3e38, -3e38, 2.0 * MAX_COORDINATE] {
            let err = CameraPath::from_json(&path(x)).unwrap_err().to_string();
            assert!(
                err.starts_with("keyframe 1 lies beyond ±1e9 scene units"),
                "{x}: {err}"
            );
        }
    }

    #[test]
    fn passes_through_keyframes() {
        let k = |x: f32| Keyframe {
            position: [x, 1.0, 0.0],
            target: [x, 1.0, -1.0],
            fov_x_deg: 40.0 + x,
        };
        let p = CameraPath {
            keyframes: vec![k(0.0), k(1.0), k(3.0)],
        };
        for (t, x) in [(0.0, 0.0), (0.5, 1.0), (1.0, 3.0)] {
            let c = p.camera(t, 8, 8);
            assert!(
                (c.origin() - Vec3::new(x, 1.0, 0.0)).length() < 1e-5,
                "t={t}"
            );
            assert!((c.fov_deg - (40.0 + x)).abs() < 1e-4);
        }
    }

    #[test]
    fn volume_path_stays_in_volume() {
        let v = CameraVolume {
            min: Vec3::new(-1.0, 0.5, 0.0),
            max: Vec3::new(1.0, 1.5, 2.0),
            look: Vec3::new(0.0, 0.0, -1.0),
            spread_deg: 30.0,
            fov_deg: 60.0,
        };
        let p = CameraPath::through_volume(&v);
        p.check().unwrap();
        for i in 0..=20 {
            let o = p.camera(i as f32 / 20.0, 4, 4).origin();
            assert!(
                o.cmpge(v.min - 1e-4).all() && o.cmple(v.max + 1e-4).all(),
                "{o}"
            );
        }
    }
}
