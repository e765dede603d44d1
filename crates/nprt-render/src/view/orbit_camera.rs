//! The viewer's camera: orbits a target, dollies towards it and flies with it.

use glam::Vec3;
use nprt_scene::Camera;

/// A camera on a sphere about `target`.
#[derive(Clone, Debug)]
pub struct OrbitCamera {
    target: Vec3,
    distance: f32,
    /// Radians about +Y, and above the horizontal plane.
    yaw: f32,
    pitch: f32,
    fov_x_deg: f32,
}

/// Where pitch stops short of straight up or down, where the view's roll is undefined.
const MAX_PITCH: f32 = 1.5;

impl OrbitCamera {
    pub fn new(eye: Vec3, target: Vec3, fov_x_deg: f32) -> Self {
        let d = eye - target;
        let distance = d.length().max(1e-3);
        OrbitCamera {
            target,
            distance,
            yaw: d.x.atan2(d.z),
            pitch: (d.y / distance)
                .clamp(-1.0, 1.0)
                .asin()
                .clamp(-MAX_PITCH, MAX_PITCH),
            fov_x_deg,
        }
    }

    pub fn eye(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + self.distance * Vec3::new(cp * sy, sp, cp * cy)
    }

    /// Turns about the target by mouse motion in pixels.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.yaw -= dx * 0.01;
        self.pitch = (self.pitch + dy * 0.01).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Moves towards (factor < 1) or away from the target.
    pub fn dolly(&mut self, factor: f32) {
        self.distance = (self.distance * factor).max(1e-2);
    }

    /// Moves eye and target together: along the view, to the right and up, in steps of a
    /// twentieth of the distance to the target.
    pub fn fly(&mut self, forward: f32, right: f32, up: f32) {
        let dir = (self.target - self.eye()).normalize();
        let side = dir.cross(Vec3::Y).normalize_or_zero();
        self.target += (dir * forward + side * right + Vec3::Y * up) * (0.05 * self.distance);
    }

    pub fn camera(&self, width: u32, height: u32) -> Camera {
        Camera::look_at(
            self.eye(),
            self.target,
            Vec3::Y,
            self.fov_x_deg,
            width,
            height,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn starts_where_it_was_put_and_orbits_at_its_distance() {
        let (eye, target) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.5, 1.0, -1.0));
        let mut c = OrbitCamera::new(eye, target, 60.0);
        assert!((c.eye() - eye).length() < 1e-5, "{}", c.eye());
        let d = (eye - target).length();
        c.orbit(40.0, -25.0);
        assert!(((c.eye() - target).length() - d).abs() < 1e-4);
        assert!((c.eye() - eye).length() > 0.1);
        c.dolly(0.5);
        assert!(((c.eye() - target).length() - d / 2.0).abs() < 1e-4);
        let before = c.eye();
        c.fly(1.0, 0.0, 0.0);
        let moved = c.eye() - before;
        let view = (target - before).normalize();
        assert!(moved.normalize().dot(view) > 0.999, "flies along the view");
        c.orbit(0.0, 1e4);
        assert!(
            c.eye().is_finite() && c.camera(8, 6).to_world.is_finite(),
            "pitch stops short of vertical"
        );
    }
}
