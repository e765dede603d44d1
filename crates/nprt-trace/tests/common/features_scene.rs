//! A scene with one mesh per material feature and scattering (bitmaps through uv transforms,
//! checkerboards, metallic-roughness, a conductor, a rough plastic, glass, opacity masks, bump
//! maps seen from either side, one- and two-sided surfaces, meshes without normals or uvs), and
//! cameras around it: what the GPU frame path's tests hold against the CPU tracer.

use std::sync::Arc;

use glam::{Affine2, Mat4, Vec2, Vec3};
use nprt_scene::{Bitmap, BumpMap, Camera, Material, Mesh, Scattering, Scene, Surface, Texture};

/// A `width` × `height` bitmap of values that vary from texel to texel (seeded by `salt`).
pub fn bitmap(width: usize, height: usize, salt: u32) -> Arc<Bitmap> {
    let texels = (0..width * height)
        .map(|i| {
            let h = |k: u32| {
                let x =
                    (i as u32).wrapping_mul(2_654_435_761) ^ (salt * 8 + k).wrapping_mul(40_503);
                (x % 1000) as f32 / 1000.0
            };
            Vec3::new(h(1), h(2), h(3))
        })
        .collect();
    Arc::new(Bitmap {
        width,
        height,
        texels,
    })
}

pub fn bitmap_texture(width: usize, height: usize, salt: u32, to_uv: Affine2) -> Texture {
    Texture::Bitmap {
        image: bitmap(width, height, salt),
        to_uv,
        factor: Vec3::new(0.9, 0.7, 0.8),
    }
}

/// One mesh per material feature, in view of [`views`].
pub fn features_scene() -> Scene {
    let mut scene = Scene::empty("features");
    // A textured floor: bitmap kd through a rotated, scaled uv, a checkerboard ks.
    let mut floor = Mesh::rectangle();
    floor.transform(
        Mat4::from_scale(Vec3::splat(3.0)) * Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2),
    );
    let tilted =
        Affine2::from_scale_angle_translation(Vec2::new(3.0, 2.0), 0.4, Vec2::new(0.1, 0.3));
    let mut textured = Material::new(
        "textured",
        Surface::Direct {
            kd: bitmap_texture(13, 9, 1, tilted),
            ks: Texture::Checkerboard {
                color0: Vec3::new(0.2, 0.1, 0.05),
                color1: Vec3::new(0.01, 0.3, 0.1),
                to_uv: Affine2::from_scale(Vec2::splat(4.0)),
            },
            alpha: Texture::constant(0.2),
        },
        true,
    );
    textured.scattering = Scattering::FresnelFree;
    scene.add(floor, textured);
    // A bumped metallic-roughness sphere, two-sided.
    let mut sphere = Material::new(
        "metal-rough",
        Surface::MetallicRoughness {
            base: bitmap_texture(16, 8, 2, Affine2::IDENTITY),
            metallic_roughness: bitmap_texture(7, 5, 3, Affine2::from_scale(Vec2::splat(2.0))),
        },
        true,
    );
    sphere.bump = Some(BumpMap {
        height: bitmap_texture(32, 16, 4, Affine2::IDENTITY),
        scale: 0.02,
        mirrored_behind: false,
    });
    scene.add(Mesh::sphere(Vec3::new(-1.0, 0.8, 0.0), 0.8, 24), sphere);
    // A one-sided conductor cube.
    let mut cube = Mesh::cube();
    cube.transform(
        Mat4::from_translation(Vec3::new(1.2, 0.5, -0.5)) * Mat4::from_scale(Vec3::splat(0.5)),
    );
    let mut conductor = Material::glossy("gold", Vec3::ZERO, Vec3::ONE, 0.05);
    conductor.two_sided = false;
    conductor.scattering = Scattering::Conductor {
        eta: Vec3::new(0.14, 0.37, 1.44),
        k: Vec3::new(3.98, 2.38, 1.6),
    };
    scene.add(cube, conductor);
    // A masked plastic panel seen from behind, its bump map mirrored there (Mitsuba's
    // twosided around a bumpmap).
    let mut panel = Mesh::rectangle();
    panel.transform(
        Mat4::from_translation(Vec3::new(0.3, 1.0, 1.2))
            * Mat4::from_rotation_y(0.3)
            * Mat4::from_scale(Vec3::new(0.6, 0.8, 1.0)),
    );
    let mut plastic = Material::glossy("plastic", Vec3::new(0.5, 0.2, 0.1), Vec3::ONE, 0.1);
    plastic.scattering = Scattering::Plastic {
        eta: 1.5,
        rough: true,
        nonlinear: false,
        sampling_weight: 0.5,
    };
    plastic.opacity = Some(bitmap_texture(8, 8, 5, Affine2::IDENTITY));
    plastic.bump = Some(BumpMap {
        height: bitmap_texture(9, 11, 6, Affine2::from_scale(Vec2::splat(3.0))),
        scale: 0.05,
        mirrored_behind: true,
    });
    scene.add(panel, plastic);
    // A one-sided panel facing away (seen from behind, not flipped).
    let mut back = Mesh::rectangle();
    back.transform(
        Mat4::from_translation(Vec3::new(-0.5, 0.6, 1.5)) * Mat4::from_scale(Vec3::splat(0.3)),
    );
    back.flip_normals();
    let mut one_sided = Material::glossy("one-sided", Vec3::splat(0.6), Vec3::splat(0.1), 0.3);
    one_sided.two_sided = false;
    scene.add(back, one_sided);
    // Flat shading without uvs: a cube with neither normals nor uvs, under a dielectric.
    let mut bare = Mesh::cube();
    bare.transform(
        Mat4::from_translation(Vec3::new(0.0, 0.3, -1.2)) * Mat4::from_scale(Vec3::splat(0.3)),
    );
    bare.normals.clear();
    bare.uvs.clear();
    let mut glass = Material::glossy("glass", Vec3::ZERO, Vec3::ONE, 0.001);
    glass.scattering = Scattering::Dielectric {
        eta: 1.5,
        thin: false,
    };
    scene.add(bare, glass);
    scene
}

/// Cameras around `scene`'s bounds at `width` × `height`, from outside and from within.
pub fn views(scene: &Scene, width: u32, height: u32) -> Vec<Camera> {
    let (lo, hi) = scene.bounds();
    let at = |f: Vec3| lo + (hi - lo) * f;
    [
        (Vec3::new(0.5, 0.7, 1.4), Vec3::new(0.5, 0.2, 0.4)),
        (Vec3::new(0.1, 0.4, 0.9), Vec3::new(0.7, 0.3, 0.2)),
        (Vec3::new(0.9, 0.5, 0.1), Vec3::new(0.2, 0.4, 0.8)),
    ]
    .into_iter()
    .map(|(eye, target)| Camera::look_at(at(eye), at(target), Vec3::Y, 60.0, width, height))
    .collect()
}
