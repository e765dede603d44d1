//! Camera placement as the paper does it: a position drawn uniformly in the active volume, a
//! view direction drawn uniformly in yaw and pitch within the pyramid around the main
//! direction; cameras inside or touching geometry are rejected and redrawn.
//!
//! Each view's camera depends only on (seed, view index), so shards of a dataset and runs with
//! any thread count place identical cameras.

use glam::{Quat, Vec3};
use nprt_scene::{Camera, CameraVolume};
use nprt_trace::TraceScene;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Minimum free distance around a camera, as a fraction of the scene's bounding diagonal.
const CLEARANCE: f32 = 0.01;
/// Draws per view before giving up.
const MAX_ATTEMPTS: u32 = 10_000;

#[derive(Debug, Clone, PartialEq)]
pub enum PlacementError {
    /// No draw left the camera outside geometry with clearance: the volume is likely inside
    /// an object or too tight.
    NoFreeSpot { view: u64, attempts: u32 },
}

impl std::fmt::Display for PlacementError {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            PlacementError::NoFreeSpot { view, attempts } => write!(
                f,
                "could not place camera {view} after {attempts} draws: every position was inside or within clearance of geometry; check the active volume"
            ),
        }
    }
}

impl std::error::Error for PlacementError {}

/// The 26 directions to the faces, edges and corners of a cube: probes for nearby geometry.
fn probe_directions() -> impl Iterator<Item = Vec3> {
    (0..27).filter(|&i| i != 13).map(|i| {
        Vec3::new(
            (i % 3) as f32 - 1.0,
            ((i / 3) % 3) as f32 - 1.0,
            (i / 9) as f32 - 1.0,
        )
        .normalize()
    })
}

/// Whether a camera at `p` is free: no surface within `clearance`, and no probe sees the back
/// of a surface (which means `p` is inside a closed object or behind a wall).
fn is_free(ts: &TraceScene, p: Vec3, clearance: f32) -> bool {
    probe_directions().all(|d| match ts.accel.intersect(p, d, f32::INFINITY) {
        None => true,
        Some(hit) => {
            let mesh = &ts.scene.meshes[hit.mesh as usize];
            let v = mesh.indices[hit.tri as usize].map(|i| mesh.positions[i as usize]);
            let facing_us = (v[1] - v[0]).cross(v[2] - v[0]).dot(d) < 0.0;
            hit.t > clearance && facing_us
        }
    })
}

/// Places the camera of view `view` for a dataset drawn with `seed`.
pub fn place_camera(
    ts: &TraceScene,
    volume: &CameraVolume,
    seed: u64,
    view: u64,
    width: u32,
    height: u32,
) -> Result<Camera, PlacementError> {
    let mut rng =
        Pcg64Mcg::seed_from_u64(seed ^ view.wrapping_mul(0x9e37_79b9_7f4a_7c15).rotate_left(17));
    let (lo, hi) = ts.scene.bounds();
    let clearance = CLEARANCE * (hi - lo).length();
    let spread = volume.spread_deg.to_radians();
    // Yaw about +Y and pitch about the main direction's horizontal right axis.
    let right = volume.look.cross(Vec3::Y).normalize_or(Vec3::X);
    for _ in 0..MAX_ATTEMPTS {
        let t = Vec3::new(rng.random(), rng.random(), rng.random());
        let p = volume.min + (volume.max - volume.min) * t;
        let yaw = (rng.random::<f32>() * 2.0 - 1.0) * spread;
        let pitch = (rng.random::<f32>() * 2.0 - 1.0) * spread;
        if !is_free(ts, p, clearance) {
            continue;
        }
        let dir = Quat::from_axis_angle(Vec3::Y, yaw)
            * (Quat::from_axis_angle(right, pitch) * volume.look);
        return Ok(Camera::look_at(
            p,
            p + dir,
            Vec3::Y,
            volume.fov_deg,
            width,
            height,
        ));
    }
    Err(PlacementError::NoFreeSpot {
        view,
        attempts: MAX_ATTEMPTS,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;
    use nprt_scene::builtin;

    fn forward(c: &Camera) -> Vec3 {
        c.ray(Vec2::new(c.width as f32 / 2.0, c.height as f32 / 2.0))
            .1
    }

    #[test]
    fn cameras_stay_in_the_volume_and_pyramid_clear_of_geometry() {
        let scene = builtin::scene("room").unwrap();
        let ts = TraceScene::new(&scene);
        let vol = scene.camera_volume.clone().unwrap();
        let (lo, hi) = scene.bounds();
        let clearance = CLEARANCE * (hi - lo).length();
        for view in 0..200 {
            let c = place_camera(&ts, &vol, 5, view, 64, 64).unwrap();
            let p = c.origin();
            assert!(p.cmpge(vol.min).all() && p.cmple(vol.max).all(), "{p}");
            let angle = forward(&c).angle_between(vol.look).to_degrees();
            // Yaw and pitch each within the spread: at most √2·spread off the main direction.
            assert!(
                angle <= vol.spread_deg * 1.5,
                "view {view} looks {angle}° off"
            );
            for d in probe_directions() {
                if let Some(h) = ts.accel.intersect(p, d, f32::INFINITY) {
                    assert!(h.t > clearance, "view {view} touches geometry");
                }
            }
        }
    }

    #[test]
    fn a_view_depends_only_on_seed_and_index() {
        let scene = builtin::scene("room").unwrap();
        let ts = TraceScene::new(&scene);
        let vol = scene.camera_volume.clone().unwrap();
        let a = place_camera(&ts, &vol, 9, 42, 32, 32).unwrap();
        let b = place_camera(&ts, &vol, 9, 42, 32, 32).unwrap();
        let c = place_camera(&ts, &vol, 9, 43, 32, 32).unwrap();
        let d = place_camera(&ts, &vol, 10, 42, 32, 32).unwrap();
        assert_eq!(a.to_world, b.to_world);
        assert_ne!(a.to_world, c.to_world);
        assert_ne!(a.to_world, d.to_world);
    }

    #[test]
    fn cameras_are_never_placed_inside_objects() {
        let scene = builtin::scene("room").unwrap();
        let ts = TraceScene::new(&scene);
        // A volume inside the blue ball (centre (-0.4, 0.35, -0.3), radius 0.35).
        let inside = CameraVolume {
            min: Vec3::new(-0.5, 0.3, -0.4),
            max: Vec3::new(-0.3, 0.4, -0.2),
            ..scene.camera_volume.clone().unwrap()
        };
        let err = place_camera(&ts, &inside, 1, 7, 32, 32).unwrap_err();
        assert_eq!(
            err,
            PlacementError::NoFreeSpot {
                view: 7,
                attempts: MAX_ATTEMPTS
            }
        );
        assert!(err.to_string().contains("camera 7"));
    }
}
