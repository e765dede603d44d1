//! Scenes made in code, so the demo and tests need no files.
//!
//! `room`: a 6 × 3 × 6 m interior, open to the environment through a missing front wall, a
//! window in the right wall and a skylight; a textured plank floor; diffuse objects; glossy
//! objects from α = 0.05 to 0.5; and a near-mirror panel (α = 0.01) on the back wall. About 20 K triangles, sized to render
//! fast on a laptop CPU.

use std::sync::Arc;

use anyhow::{bail, Result};
use glam::{Affine2, Mat4, Quat, Vec3};

use crate::camera::{Camera, CameraVolume};
use crate::material::{Material, Surface};
use crate::mesh::Mesh;
use crate::procedural::{sky, SkyParams};
use crate::scene::Scene;
use crate::texture::{Bitmap, Texture};

pub const NAMES: &[&str] = &["room"];

pub fn scene(name: &str) -> Result<Scene> {
    match name {
        "room" => room(),
        _ => bail!(
            "unknown built-in scene 'builtin:{name}' (available: {})",
            NAMES
                .iter()
                .map(|n| format!("builtin:{n}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// An axis-aligned wall panel: a rectangle scaled to `size` (x, y), rotated by `rot`, placed at
/// `centre`.
fn panel(size: (f32, f32), rot: Quat, centre: Vec3) -> Mesh {
    let mut m = Mesh::rectangle();
    m.transform(
        Mat4::from_translation(centre)
            * Mat4::from_quat(rot)
            * Mat4::from_scale(Vec3::new(size.0 / 2.0, size.1 / 2.0, 1.0)),
    );
    m
}

/// Wooden planks: stripes of varying tone with thin dark seams, in linear RGB.
fn plank_texture() -> Bitmap {
    let (w, h) = (256usize, 256usize);
    let planks = 8;
    let mut texels = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let plank = x * planks / w;
            // Deterministic per-plank tone and along-plank grain.
            let tone = 0.75 + 0.25 * (((plank * 7919) % 13) as f32 / 12.0);
            let grain = 0.9
                + 0.1 * ((y as f32 * 0.15 + plank as f32 * 1.7).sin() * (x as f32 * 0.05).cos());
            let seam = if x % (w / planks) == 0 || (y + plank * 37) % h == 0 {
                0.3
            } else {
                1.0
            };
            texels.push(Vec3::new(0.45, 0.28, 0.14) * tone * grain * seam);
        }
    }
    Bitmap {
        width: w,
        height: h,
        texels,
    }
}

fn room() -> Result<Scene> {
    let mut s = Scene::empty("builtin:room");
    let half = 3.0f32;
    room_shell(&mut s, half, 3.0);
    room_objects(&mut s, half);
    s.camera = Some(Camera::look_at(
        Vec3::new(0.3, 1.5, 2.7),
        Vec3::new(-0.2, 0.8, -1.2),
        Vec3::Y,
        70.0,
        256,
        256,
    ));
    // Standing and sitting eye heights over the open half of the room, looking at the back.
    s.camera_volume = Some(CameraVolume {
        min: Vec3::new(-2.2, 0.9, -0.2),
        max: Vec3::new(2.2, 2.2, 2.8),
        look: Vec3::new(0.0, -0.25, -1.0).normalize(),
        spread_deg: 30.0,
        fov_deg: 60.0,
    });
    s.envmap = Some(sky(SkyParams::default())?);
    s.max_depth = Some(6);
    s.spp = Some(64);
    Ok(s)
}

/// The room's floor (planks), ceiling around the skylight and walls, the right one around the
/// window: a box `2 half` wide and `height` tall.
fn room_shell(s: &mut Scene, half: f32, height: f32) {
    let wall = || Material::diffuse("wall", Vec3::new(0.75, 0.72, 0.68));
    let up = Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2);
    let down = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);

    // Floor with plank texture repeated twice per metre... over 6 m.
    let floor = Material::new(
        "floor",
        Surface::Direct {
            kd: Texture::Bitmap {
                image: Arc::new(plank_texture()),
                to_uv: Affine2::from_scale(glam::Vec2::splat(2.0)),
                factor: Vec3::ONE,
            },
            ks: Texture::Constant(Vec3::splat(0.04)),
            alpha: Texture::constant(0.3),
        },
        true,
    );
    s.add(panel((2.0 * half, 2.0 * half), up, Vec3::ZERO), floor);
    // Ceiling around a 2 × 2 m skylight centred over x = 0.5, z = -1.
    let ceil_y = height;
    s.add(
        panel((2.0 * half, 1.0), down, Vec3::new(0.0, ceil_y, -2.5)),
        wall(),
    );
    s.add(
        panel((2.0 * half, 3.0), down, Vec3::new(0.0, ceil_y, 1.5)),
        wall(),
    );
    s.add(
        panel((3.5, 2.0), down, Vec3::new(-1.25, ceil_y, -1.0)),
        wall(),
    );
    s.add(
        panel((1.5, 2.0), down, Vec3::new(2.25, ceil_y, -1.0)),
        wall(),
    );
    // Back wall (z = -3) and left wall (x = -3), solid.
    s.add(
        panel(
            (2.0 * half, height),
            Quat::IDENTITY,
            Vec3::new(0.0, height / 2.0, -half),
        ),
        wall(),
    );
    s.add(
        panel(
            (2.0 * half, height),
            Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
            Vec3::new(-half, height / 2.0, 0.0),
        ),
        wall(),
    );
    // Right wall (x = +3) with a 3 m wide, 1.6 m tall window from y = 0.8 to 2.4, z in [-2, 1].
    let right = Quat::from_rotation_y(-std::f32::consts::FRAC_PI_2);
    s.add(panel((6.0, 0.8), right, Vec3::new(half, 0.4, 0.0)), wall());
    s.add(panel((6.0, 0.6), right, Vec3::new(half, 2.7, 0.0)), wall());
    s.add(panel((1.0, 1.6), right, Vec3::new(half, 1.6, -2.5)), wall());
    s.add(panel((2.0, 1.6), right, Vec3::new(half, 1.6, 2.0)), wall());
}

/// The room's objects, diffuse and glossy, and the mirror on the back wall (at z = -`half`).
fn room_objects(s: &mut Scene, half: f32) {
    // Diffuse objects: an orange box and a blue-grey ball.
    let mut cube = Mesh::cube();
    cube.transform(
        Mat4::from_translation(Vec3::new(-1.6, 0.45, -1.6))
            * Mat4::from_rotation_y(0.5)
            * Mat4::from_scale(Vec3::splat(0.45)),
    );
    s.add(
        cube,
        Material::diffuse("orange box", Vec3::new(0.7, 0.32, 0.12)),
    );
    s.add(
        Mesh::sphere(Vec3::new(-0.4, 0.35, -0.3), 0.35, 48),
        Material::diffuse("blue ball", Vec3::new(0.25, 0.35, 0.6)),
    );
    // Glossy objects, α = 0.05, 0.2, 0.5.
    s.add(
        Mesh::sphere(Vec3::new(0.9, 0.4, -1.8), 0.4, 48),
        Material::glossy("gold", Vec3::ZERO, Vec3::new(0.9, 0.7, 0.35), 0.05),
    );
    s.add(
        Mesh::sphere(Vec3::new(1.6, 0.3, -0.3), 0.3, 48),
        Material::glossy(
            "red plastic",
            Vec3::new(0.5, 0.06, 0.05),
            Vec3::splat(0.3),
            0.2,
        ),
    );
    let mut pedestal = Mesh::cube();
    pedestal.transform(
        Mat4::from_translation(Vec3::new(0.3, 0.25, -2.4))
            * Mat4::from_scale(Vec3::new(0.5, 0.25, 0.35)),
    );
    s.add(
        pedestal,
        Material::glossy("satin metal", Vec3::splat(0.05), Vec3::splat(0.6), 0.5),
    );
    // Near-mirror panel on the back wall, in the default view.
    let mirror = panel(
        (1.2, 1.0),
        Quat::IDENTITY,
        Vec3::new(1.7, 1.6, -half + 0.01),
    );
    s.add(
        mirror,
        Material::glossy("mirror", Vec3::ZERO, Vec3::splat(0.9), 0.01),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn room_has_all_ingredients() {
        let s = scene("room").unwrap();
        let params: Vec<_> = s
            .materials
            .iter()
            .map(|m| m.eval(glam::Vec2::new(0.3, 0.3)))
            .collect();
        assert!(
            params
                .iter()
                .any(|p| p.ks == Vec3::ZERO && p.kd.max_element() > 0.3),
            "diffuse objects"
        );
        for a in [0.05, 0.2, 0.5, 0.01] {
            assert!(
                params
                    .iter()
                    .any(|p| (p.alpha - a).abs() < 1e-6 && p.ks.max_element() > 0.2),
                "alpha {a}"
            );
        }
        assert!(!s.materials[0].surface_is_constant(), "textured floor");
        assert!(s.triangle_count() > 1000 && s.triangle_count() < 50_000);
        assert!(scene("nope")
            .unwrap_err()
            .to_string()
            .contains("builtin:room"));
    }
}
