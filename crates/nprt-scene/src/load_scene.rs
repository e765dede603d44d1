//! The single entry point that loads a scene from any format.

use std::path::Path;

use anyhow::{bail, Result};
use glam::Vec3;

use crate::camera::CameraVolume;
use crate::material::Material;
use crate::scene::Scene;
use crate::scene_options::SceneOptions;

/// Loads `spec`: a file (.xml Mitsuba 3, .gltf/.glb, .ply/.obj) or `builtin:NAME`. A file
/// scene's camera volume comes from its sidecar `NAME.camera.json` when there is one.
pub fn load_scene(spec: &str, opts: &SceneOptions) -> Result<Scene> {
    if let Some(name) = spec.strip_prefix("builtin:") {
        return crate::builtin::scene(name);
    }
    let path = Path::new(spec);
    if !path.exists() {
        bail!("scene file '{spec}' does not exist");
    }
    if path.is_dir() {
        bail!(
            "scene file '{spec}' is a folder; give a scene file (.xml, .gltf, .glb, .ply or .obj) \
             or builtin:room"
        );
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let mut scene = match ext.as_str() {
        "xml" => crate::mitsuba::load(path, opts)?,
        "gltf" | "glb" => crate::gltf_scene::load(path)?,
        "ply" | "obj" => {
            let mut scene = Scene::empty(spec);
            let mesh = crate::mesh_io::load_mesh(path, false)?;
            scene.add(mesh, Material::diffuse("default", Vec3::splat(0.5)));
            scene
        }
        _ => bail!(
            "scene file '{spec}': unknown format '.{ext}' (expected .xml, .gltf, .glb, .ply, .obj or builtin:{})",
            crate::builtin::NAMES.join("|builtin:")
        ),
    };
    if scene.meshes.is_empty() {
        bail!("scene file '{spec}' contains no geometry");
    }
    let clamped: Vec<String> = (scene.materials.iter_mut())
        .flat_map(|m| m.clamp_reflectances())
        .map(|w| format!("scene file '{spec}': {w}"))
        .collect();
    scene.warnings.extend(clamped);
    scene.check_extent(&format!("scene file '{spec}'"))?;
    let sidecar = CameraVolume::sidecar_of(path);
    if sidecar.exists() {
        scene.camera_volume = Some(CameraVolume::load(&sidecar)?);
    }
    Ok(scene)
}
