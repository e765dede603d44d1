//! The local shading frame: BSDFs work with z along the shading normal.

use glam::Vec3;

/// An orthonormal frame around a unit normal (Duff et al. 2017).
#[derive(Clone, Copy, Debug)]
pub struct Frame3 {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame3 {
    pub fn new(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame3 { s, t, n }
    }
    pub fn to_local(self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }
    pub fn to_world(self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}
