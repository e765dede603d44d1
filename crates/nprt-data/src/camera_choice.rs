//! Which camera volume a dataset's views are placed in: the scene's own (a built-in's, or a
//! file scene's sidecar `NAME.camera.json`), a volume file, or corners given by hand, with the
//! spread and field of view overridable on any of them.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use glam::Vec3;
use nprt_scene::{CameraVolume, Scene};

/// The volume's source and overrides; the default is the scene's own volume as it is.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CameraChoice {
    /// A camera-volume file, read instead of the scene's.
    pub file: Option<PathBuf>,
    /// Corners and main view direction given by hand (all three, or none).
    pub min: Option<Vec3>,
    pub max: Option<Vec3>,
    pub look: Option<Vec3>,
    /// Half-angle of the pyramid of view directions, degrees (default: the volume's).
    pub spread_deg: Option<f32>,
    /// Horizontal field of view of the placed cameras, degrees (default: the volume's).
    pub fov_deg: Option<f32>,
}

/// Spread and field of view of a volume given by corners alone.
const HAND_SPREAD_DEG: f32 = 30.0;
const HAND_FOV_DEG: f32 = 60.0;

impl CameraChoice {
    /// The volume for `scene` (loaded from `scene_spec`); errors say what to give instead.
    pub fn resolve(&self, scene: &Scene, scene_spec: &str) -> Result<CameraVolume> {
        let base = match (self.min, self.max, self.look, &self.file) {
            (Some(min), Some(max), Some(look), None) => CameraVolume {
                min,
                max,
                look: CameraVolume::direction(look),
                spread_deg: HAND_SPREAD_DEG,
                fov_deg: HAND_FOV_DEG,
            },
            (None, None, None, Some(file)) => CameraVolume::load(file)?,
            (None, None, None, None) => scene.camera_volume.clone().with_context(|| {
                format!(
                    "scene '{scene_spec}' carries no camera volume (no sidecar '{}'); give \
                     --camera-volume FILE or --volume-min, --volume-max and --look",
                    CameraVolume::sidecar_of(Path::new(scene_spec)).display()
                )
            })?,
            (_, _, _, Some(_)) => {
                bail!("a camera-volume file and corners given by hand exclude each other")
            }
            _ => bail!("--volume-min, --volume-max and --look go together: give all three"),
        };
        let volume = CameraVolume {
            spread_deg: self.spread_deg.unwrap_or(base.spread_deg),
            fov_deg: self.fov_deg.unwrap_or(base.fov_deg),
            ..base
        };
        if let Some(p) = volume.problem() {
            bail!("camera volume for '{scene_spec}': {p}");
        }
        Ok(volume)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nprt_scene::{load_scene, SceneOptions};

    #[test]
    fn overrides_apply_to_the_scene_volume_and_bad_ones_are_refused() {
        let scene = load_scene("builtin:room", &SceneOptions::default()).unwrap();
        let own = scene.camera_volume.clone().unwrap();
        assert_eq!(
            CameraChoice::default()
                .resolve(&scene, "builtin:room")
                .unwrap(),
            own
        );
        let narrow = CameraChoice {
            fov_deg: Some(40.0),
            spread_deg: Some(10.0),
            ..Default::default()
        };
        let v = narrow.resolve(&scene, "builtin:room").unwrap();
        assert_eq!(
            (v.fov_deg, v.spread_deg, v.min, v.max),
            (40.0, 10.0, own.min, own.max)
        );
        let by_hand = CameraChoice {
            min: Some(Vec3::ZERO),
            max: Some(Vec3::ONE),
            look: Some(Vec3::new(0.0, 0.0, -2.0)),
            ..Default::default()
        };
        let v = by_hand.resolve(&scene, "builtin:room").unwrap();
        assert_eq!((v.look, v.fov_deg), (Vec3::NEG_Z, HAND_FOV_DEG));
        let inverted = CameraChoice {
            min: Some(Vec3::ONE),
            max: Some(Vec3::ZERO),
            ..by_hand.clone()
        };
        let err = inverted
            .resolve(&scene, "builtin:room")
            .unwrap_err()
            .to_string();
        assert!(err.contains("must not exceed"), "{err}");
        let partial = CameraChoice {
            look: None,
            ..by_hand
        };
        let err = partial
            .resolve(&scene, "builtin:room")
            .unwrap_err()
            .to_string();
        assert!(err.contains("go together"), "{err}");
        let wide = CameraChoice {
            fov_deg: Some(200.0),
            ..Default::default()
        };
        assert!(wide.resolve(&scene, "builtin:room").is_err());
    }
}
