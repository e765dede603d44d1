//! Pinhole cameras with Mitsuba 3's `perspective` conventions: camera space looks along +Z
//! with +Y up and +X to the image's left; `fov` is measured along `fov_axis`.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use glam::{Mat4, Vec2, Vec3};
use serde::Deserialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FovAxis {
    X,
    Y,
    Diagonal,
    Smaller,
    Larger,
}

/// Where dataset cameras may go, as the paper places them: positions in an axis-aligned box
/// (the active volume), view directions within a square pyramid around a main direction,
/// +Y up, no roll.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraVolume {
    pub min: Vec3,
    pub max: Vec3,
    /// Main view direction (unit).
    pub look: Vec3,
    /// Half-angle of the pyramid of view directions, degrees, in yaw and in pitch.
    pub spread_deg: f32,
    /// Horizontal field of view of the placed cameras, degrees.
    pub fov_deg: f32,
}

/// A camera volume as a file scene's sidecar states it (`NAME.camera.json` beside
/// `NAME.xml`): `{"min": [x, y, z], "max": [x, y, z], "look": [x, y, z], "spread_deg": 30,
/// "fov_deg": 60}`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct VolumeFile {
    min: [f32; 3],
    max: [f32; 3],
    look: [f32; 3],
    spread_deg: f32,
    fov_deg: f32,
}

/// The farthest a camera volume's corner may lie from the origin.
const MAX_COORDINATE: f32 = 1e6;

impl CameraVolume {
    /// The sidecar that states the camera volume of the scene file `scene`.
    pub fn sidecar_of(scene: &Path) -> PathBuf {
        scene.with_extension("camera.json")
    }

    /// Reads and checks a camera-volume file; errors name the file and the reason.
    pub fn load(path: &Path) -> Result<Self> {
        let text = nprt_io::read_input_string(path)
            .with_context(|| format!("cannot read camera volume '{}'", path.display()))?;
        let f: VolumeFile = serde_json::from_str(&text)
            .with_context(|| format!("camera volume '{}'", path.display()))?;
        let v = CameraVolume {
            min: Vec3::from(f.min),
            max: Vec3::from(f.max),
            look: CameraVolume::direction(Vec3::from(f.look)),
            spread_deg: f.spread_deg,
            fov_deg: f.fov_deg,
        };
        if let Some(p) = v.problem() {
            bail!("camera volume '{}': {p}", path.display());
        }
        Ok(v)
    }

    /// `look` as a unit direction, normalised in double precision: a finite direction of any
    /// size is one (its length overflowed f32 at [10³⁸; 3]); zero or not finite stays zero,
    /// which [`problem`](Self::problem) refuses.
    pub fn direction(look: Vec3) -> Vec3 {
        look.as_dvec3().normalize_or_zero().as_vec3()
    }

    /// What makes this volume unusable, if anything: the rule each field breaks. The one check
    /// of a camera volume, wherever one is read (a sidecar, flags, a dataset's manifest).
    pub fn problem(&self) -> Option<&'static str> {
        if !(self.min.is_finite() && self.max.is_finite() && self.min.cmple(self.max).all()) {
            Some("\"min\" must not exceed \"max\" on any axis")
        } else if self.min.abs().max(self.max.abs()).max_element() > MAX_COORDINATE {
            Some("\"min\" and \"max\" must lie within ±10⁶ (f32 rays lose their precision beyond)")
        } else if !self.look.is_finite() || self.look == Vec3::ZERO {
            Some("\"look\" must be a non-zero direction")
        } else if !(self.spread_deg >= 0.0 && self.spread_deg < 90.0) {
            Some("\"spread_deg\" must be in [0, 90)")
        } else if !(self.fov_deg > 0.0 && self.fov_deg < 180.0) {
            Some("\"fov_deg\" must be in (0, 180)")
        } else {
            None
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub to_world: Mat4,
    pub fov_deg: f32,
    pub fov_axis: FovAxis,
    pub width: u32,
    pub height: u32,
}

/// Mitsuba's `lookat`: columns (left, up, forward, origin). Looking along `up` itself (straight
/// up or down with +Y up) leaves the roll undefined, where Mitsuba's frame is NaN; the world
/// axis least aligned with the view then serves as up, so the frame stays well defined.
pub fn look_at(origin: Vec3, target: Vec3, up: Vec3) -> Mat4 {
    let dir = (target - origin).normalize();
    let left = up.cross(dir).try_normalize().unwrap_or_else(|| {
        let a = dir.abs();
        let axis = if a.x <= a.y && a.x <= a.z {
            Vec3::X
        } else if a.y <= a.z {
            Vec3::Y
        } else {
            Vec3::Z
        };
        axis.cross(dir).normalize()
    });
    let new_up = dir.cross(left);
    Mat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        origin.extend(1.0),
    )
}

impl Camera {
    pub fn look_at(
        origin: Vec3,
        target: Vec3,
        up: Vec3,
        fov_x_deg: f32,
        width: u32,
        height: u32,
    ) -> Self {
        Camera {
            to_world: look_at(origin, target, up),
            fov_deg: fov_x_deg,
            fov_axis: FovAxis::X,
            width,
            height,
        }
    }

    /// tan of half the horizontal field of view.
    pub fn tan_half_x(&self) -> f32 {
        let (w, h) = (self.width as f32, self.height as f32);
        let t = (self.fov_deg.to_radians() * 0.5).tan();
        let axis = match self.fov_axis {
            FovAxis::Smaller if w > h => FovAxis::Y,
            FovAxis::Smaller => FovAxis::X,
            FovAxis::Larger if w > h => FovAxis::X,
            FovAxis::Larger => FovAxis::Y,
            a => a,
        };
        match axis {
            FovAxis::Y => t * w / h,
            FovAxis::Diagonal => t * w / (w * w + h * h).sqrt(),
            _ => t,
        }
    }

    pub fn origin(&self) -> Vec3 {
        self.to_world.transform_point3(Vec3::ZERO)
    }

    /// Primary ray through film position `film` in pixels ((0,0) is the top-left corner):
    /// (origin, unit direction).
    pub fn ray(&self, film: Vec2) -> (Vec3, Vec3) {
        let tx = self.tan_half_x();
        let ty = tx * self.height as f32 / self.width as f32;
        let sx = film.x / self.width as f32;
        let sy = film.y / self.height as f32;
        let local = Vec3::new((0.5 - sx) * 2.0 * tx, (0.5 - sy) * 2.0 * ty, 1.0);
        (
            self.origin(),
            self.to_world.transform_vector3(local).normalize(),
        )
    }

    /// A copy rendering at another resolution (same field of view along its axis).
    pub fn with_resolution(&self, width: u32, height: u32) -> Self {
        Camera {
            width,
            height,
            ..self.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A camera looking straight up or down along its up vector (a camera path keyframe with
    /// its target above it) still has an orthonormal frame and finite rays.
    /// A finite direction of any size is a direction: [10³⁸; 3]'s length overflowed f32 and
    /// it was refused as "must be a non-zero direction".
    #[test]
    fn a_look_direction_of_any_finite_size_is_normalised() {
        for look in [
            Vec3::splat(1e38),
            Vec3::splat(-3e38),
            Vec3::new(1e-40, 0.0, 0.0),
        ] {
            let d = CameraVolume::direction(look);
            assert!((d.length() - 1.0).abs() < 1e-6, "{look} → {d}");
            assert!(d.dot(look.signum()) > 0.0, "{look} → {d}");
        }
        for look in [
            Vec3::ZERO,
            Vec3::new(f32::NAN, 1.0, 0.0),
            Vec3::new(f32::INFINITY, 0.0, 0.0),
        ] {
            assert_eq!(CameraVolume::direction(look), Vec3::ZERO, "{look}");
        }
    }

    #[test]
    fn looking_along_up_gives_a_finite_frame() {
        for target in [Vec3::new(0.0, 2.0, 1.0), Vec3::new(0.0, -3.0, 1.0)] {
            let c = Camera::look_at(Vec3::new(0.0, 1.0, 1.0), target, Vec3::Y, 60.0, 8, 8);
            let m = c.to_world;
            let (l, u, f) = (
                m.x_axis.truncate(),
                m.y_axis.truncate(),
                m.z_axis.truncate(),
            );
            for (a, b) in [(l, u), (u, f), (f, l)] {
                assert!(a.dot(b).abs() < 1e-6, "{m:?}");
            }
            assert!((f - (target - Vec3::new(0.0, 1.0, 1.0)).normalize()).length() < 1e-6);
            let (o, d) = c.ray(glam::Vec2::new(1.5, 6.5));
            assert!(o.is_finite() && d.is_finite() && (d.length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn centre_ray_looks_at_target_and_left_is_left() {
        let c = Camera::look_at(Vec3::new(0., 0., 5.), Vec3::ZERO, Vec3::Y, 90.0, 200, 100);
        let (o, d) = c.ray(Vec2::new(100.0, 50.0));
        assert_eq!(o, Vec3::new(0., 0., 5.));
        assert!((d - -Vec3::Z).length() < 1e-6);
        // Looking down -Z with +Y up, the image's left edge sees -X, its top edge +Y.
        let (_, left) = c.ray(Vec2::new(0.0, 50.0));
        assert!(
            (left - Vec3::new(-1.0, 0.0, -1.0).normalize()).length() < 1e-5,
            "{left}"
        );
        let (_, top) = c.ray(Vec2::new(100.0, 0.0));
        assert!(top.y > 0.0);
    }

    #[test]
    fn fov_axis_y_is_vertical() {
        let mut c = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 90.0, 200, 100);
        c.fov_axis = FovAxis::Y;
        let (_, top) = c.ray(Vec2::new(100.0, 0.0));
        assert!((top.y - top.z).abs() < 1e-5, "{top}");
    }

    /// A file scene picks up its sidecar volume; bad volumes are refused with the file named.
    #[test]
    fn camera_volume_sidecar_is_read_and_checked() {
        let dir = std::env::temp_dir().join(format!("nprt-volume-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let scene = dir.join("room.xml");
        std::fs::write(
            &scene,
            r#"<scene version="3.0.0"><shape type="cube"/></scene>"#,
        )
        .unwrap();
        let spec = scene.to_str().unwrap();
        let opts = crate::SceneOptions::default();
        assert!(crate::load_scene(spec, &opts)
            .unwrap()
            .camera_volume
            .is_none());
        let sidecar = CameraVolume::sidecar_of(&scene);
        assert_eq!(sidecar, dir.join("room.camera.json"));
        let good = r#"{"min": [-1, 0.5, -1], "max": [1, 2, 1], "look": [0, 0, -2], "spread_deg": 20, "fov_deg": 50}"#;
        std::fs::write(&sidecar, good).unwrap();
        let v = crate::load_scene(spec, &opts)
            .unwrap()
            .camera_volume
            .unwrap();
        assert_eq!(
            (v.min, v.look, v.spread_deg, v.fov_deg),
            (Vec3::new(-1.0, 0.5, -1.0), -Vec3::Z, 20.0, 50.0)
        );
        for (bad, why) in [
            (good.replace("[1, 2, 1]", "[1, 0, 1]"), "must not exceed"),
            (good.replace("[0, 0, -2]", "[0, 0, 0]"), "non-zero"),
            (
                good.replace("\"fov_deg\": 50", "\"fov_deg\": 180"),
                "fov_deg",
            ),
            (
                good.replace("\"spread_deg\"", "\"spread\""),
                "unknown field",
            ),
        ] {
            std::fs::write(&sidecar, bad).unwrap();
            let err = format!("{:#}", crate::load_scene(spec, &opts).unwrap_err());
            assert!(
                err.contains("room.camera.json") && err.contains(why),
                "{err}"
            );
        }
    }
}
