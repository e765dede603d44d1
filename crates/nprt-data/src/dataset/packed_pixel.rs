//! One foreground pixel of a packed dataset (docs/dataset.md, "Packed datasets"): 40 bytes that
//! decode to the pixel's G-buffer sample and the radiance a network learns. Each input is kept
//! at the precision its use needs, far below the reference's own noise: the position as 16-bit
//! fixed point within the scene bounds, the two directions octahedral in 2 × 16 bits, kd, ks and
//! α in f16; the radiance stays f32.

use glam::{Vec2, Vec3};
use half::f16;
use nprt_trace::GSample;

/// The record as it lies in the file (little-endian, no padding).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct PackedPixel {
    /// (x − min) / (max − min) of the scene bounds, as 0..=65535.
    pub position: [u16; 3],
    /// Octahedral map of the unit normal, each coordinate as −32767..=32767.
    pub normal: [i16; 2],
    /// ωo, the unit direction towards the camera, likewise.
    pub view: [i16; 2],
    /// f16 bits.
    pub kd: [u16; 3],
    pub ks: [u16; 3],
    pub alpha: u16,
    /// What the network learns (the [`PackedTarget`](super::PackedTarget) of the pack).
    pub radiance: [f32; 3],
}

/// Bytes a record takes.
pub const PACKED_PIXEL_BYTES: usize = std::mem::size_of::<PackedPixel>();

impl PackedPixel {
    /// The record of G-buffer sample `s` (a foreground pixel inside `bounds`) learning `radiance`.
    pub fn encode(s: &GSample, radiance: Vec3, bounds: &[[f32; 3]; 2]) -> Self {
        let (lo, extent) = frame(bounds);
        let unit = ((s.position - lo) / extent.max(Vec3::splat(f32::MIN_POSITIVE)))
            .clamp(Vec3::ZERO, Vec3::ONE);
        let half3 = |v: Vec3| v.to_array().map(|x| f16::from_f32(x).to_bits());
        PackedPixel {
            position: unit.to_array().map(|u| (u * 65535.0).round() as u16),
            normal: octahedral(s.normal),
            view: octahedral(s.view),
            kd: half3(s.kd),
            ks: half3(s.ks),
            alpha: f16::from_f32(s.alpha).to_bits(),
            radiance: radiance.to_array(),
        }
    }

    /// The G-buffer sample and the radiance this record holds, `bounds` being those it was
    /// encoded with.
    pub fn decode(&self, bounds: &[[f32; 3]; 2]) -> (GSample, Vec3) {
        let (lo, extent) = frame(bounds);
        let unit = Vec3::from(self.position.map(|u| u as f32 / 65535.0));
        let vec3 = |h: [u16; 3]| Vec3::from(h.map(|b| f16::from_bits(b).to_f32()));
        let sample = GSample {
            position: lo + unit * extent,
            normal: from_octahedral(self.normal),
            view: from_octahedral(self.view),
            kd: vec3(self.kd),
            ks: vec3(self.ks),
            alpha: f16::from_bits(self.alpha).to_f32(),
            mask: 1.0,
        };
        (sample, Vec3::from(self.radiance))
    }
}

/// The bounds' minimum and extent.
fn frame(bounds: &[[f32; 3]; 2]) -> (Vec3, Vec3) {
    let lo = Vec3::from(bounds[0]);
    (lo, Vec3::from(bounds[1]) - lo)
}

/// The octahedral map of a direction (Meyer et al. 2010), each coordinate quantised to 16 bits.
fn octahedral(d: Vec3) -> [i16; 2] {
    let sum = d.x.abs() + d.y.abs() + d.z.abs();
    if sum.is_nan() || sum <= 0.0 {
        return [0, 0];
    }
    let p = Vec2::new(d.x, d.y) / sum;
    let p = if d.z >= 0.0 {
        p
    } else {
        (Vec2::ONE - Vec2::new(p.y.abs(), p.x.abs())) * sign(p)
    };
    p.to_array()
        .map(|c| (c.clamp(-1.0, 1.0) * 32767.0).round() as i16)
}

fn from_octahedral(q: [i16; 2]) -> Vec3 {
    let p = Vec2::from(q.map(|c| c as f32 / 32767.0));
    let z = 1.0 - p.x.abs() - p.y.abs();
    let xy = if z >= 0.0 {
        p
    } else {
        (Vec2::ONE - Vec2::new(p.y.abs(), p.x.abs())) * sign(p)
    };
    Vec3::new(xy.x, xy.y, z).normalize()
}

/// ±1 per coordinate, +1 at zero.
fn sign(p: Vec2) -> Vec2 {
    Vec2::new(
        if p.x >= 0.0 { 1.0 } else { -1.0 },
        if p.y >= 0.0 { 1.0 } else { -1.0 },
    )
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Directions spread over the whole sphere (a Fibonacci lattice) plus the axes, whose
    /// coordinates sit on the octahedron's folds.
    fn directions() -> Vec<Vec3> {
        let n = 20_000;
        let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
        let mut d: Vec<Vec3> = (0..n)
            .map(|i| {
                let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let r = (1.0 - y * y).sqrt();
                let phi = golden * i as f32;
                Vec3::new(r * phi.cos(), y, r * phi.sin())
            })
            .collect();
        d.extend([Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z]);
        d
    }

    /// The angle between two unit vectors, precise near zero (unlike acos of the dot product).
    pub(crate) fn angle(a: Vec3, b: Vec3) -> f32 {
        a.cross(b).length().atan2(a.dot(b))
    }

    #[test]
    fn every_input_comes_back_within_its_stated_precision() {
        let bounds = [[-2.0, 0.0, -3.0], [2.0, 2.5, 3.0]];
        let mut worst_angle = 0.0f32;
        for (i, d) in directions().into_iter().enumerate() {
            let t = i as f32 / 20_006.0;
            let s = GSample {
                position: Vec3::new(-2.0 + 4.0 * t, 2.5 * (1.0 - t), 6.0 * t * t - 3.0),
                normal: d,
                view: -d,
                kd: Vec3::new(t, 0.5 * t, 1.0 - t),
                ks: Vec3::splat(0.04 + 0.9 * t),
                alpha: 0.001 + t,
                mask: 1.0,
            };
            let radiance = Vec3::new(1e-3, 7.5, 1234.5) * t;
            let (back, r) = PackedPixel::encode(&s, radiance, &bounds).decode(&bounds);
            assert_eq!(r, radiance, "the radiance is kept exactly");
            // Half a step of 16-bit fixed point over the bounds (extent 6 at most).
            let err = (back.position - s.position).abs().max_element();
            assert!(err <= 6.0 / 65535.0 * 0.5 + 1e-6, "position error {err}");
            for (a, b) in [(back.normal, s.normal), (back.view, s.view)] {
                worst_angle = worst_angle.max(angle(a, b));
            }
            // f16 keeps 11 significant bits.
            for (a, b) in [(back.kd, s.kd), (back.ks, s.ks)] {
                let rel = ((a - b).abs() / b.abs().max(Vec3::splat(1e-3))).max_element();
                assert!(rel <= 1.0 / 2048.0, "{a} against {b}");
            }
            assert!((back.alpha - s.alpha).abs() <= s.alpha / 2048.0);
            assert_eq!(back.mask, 1.0);
        }
        // 16-bit octahedral directions: 6.3e-5 radians at most here (0.0036°), as Cigolle et
        // al. (2014) measured for this map.
        assert!(
            worst_angle < 1e-4,
            "worst direction error {worst_angle} rad"
        );
    }

    #[test]
    fn a_record_is_forty_bytes_without_padding() {
        assert_eq!(PACKED_PIXEL_BYTES, 40);
        assert_eq!(std::mem::align_of::<PackedPixel>(), 4);
    }

    #[test]
    fn flat_bounds_and_degenerate_directions_decode_to_finite_values() {
        let bounds = [[0.0, 1.0, 0.0], [1.0, 1.0, 1.0]];
        let s = GSample {
            position: Vec3::new(0.5, 1.0, 0.25),
            ..GSample::default()
        };
        let (back, _) = PackedPixel::encode(&s, Vec3::ZERO, &bounds).decode(&bounds);
        assert_eq!(back.position.y, 1.0);
        assert!(back.normal.is_finite() && back.view.is_finite());
    }
}
