//! What identifies the scene a dataset was rendered from (and a model trained on): its source
//! bytes and a hash of what the network learns.

use anyhow::{bail, Context, Result};
use nprt_scene::Scene;

/// Source bytes that identify a scene: the file's bytes, or the built-in name.
pub fn scene_source(spec: &str) -> Result<Vec<u8>> {
    if spec.starts_with("builtin:") {
        Ok(spec.as_bytes().to_vec())
    } else {
        nprt_io::read_input(std::path::Path::new(spec))
            .with_context(|| format!("cannot read scene '{spec}'"))
    }
}

/// Loads the scene `spec` and checks it is the one with hash `expected` (that a dataset was
/// rendered from, or a model trained on, as `what` says). Its own lighting is not read: a
/// dataset's views, and a model's frames, are lit by maps of their own.
pub fn load_checked_scene(spec: &str, expected: &str, what: &str) -> Result<Scene> {
    let scene = nprt_scene::load_scene(spec, &relit())?;
    let hash = scene_hash(&scene, &scene_source(spec)?);
    if hash != expected {
        bail!(
            "scene '{spec}' is not the scene {what} (hash {} ≠ {})",
            &hash[..12],
            &expected[..12.min(expected.len())]
        );
    }
    Ok(scene)
}

/// How a scene is read for datasets and models: lit by their own maps, so the scene's
/// environment emitter is skipped (its map file need not exist).
pub fn relit() -> nprt_scene::SceneOptions {
    nprt_scene::SceneOptions {
        lighting_replaced: true,
        ..Default::default()
    }
}

/// Hash of what the network will learn: geometry, material parameters at vertices, and the
/// scene's source text (file bytes, or the built-in name).
pub fn scene_hash(scene: &Scene, source: &[u8]) -> String {
    let mut h = blake3::Hasher::new();
    h.update(source);
    for m in &scene.meshes {
        for p in &m.positions {
            h.update(&p.x.to_le_bytes())
                .update(&p.y.to_le_bytes())
                .update(&p.z.to_le_bytes());
        }
        for t in &m.indices {
            t.iter().for_each(|i| {
                h.update(&i.to_le_bytes());
            });
        }
        let mat = &scene.materials[m.material];
        for uv in m
            .uvs
            .iter()
            .take(64)
            .chain(std::iter::once(&glam::Vec2::ZERO))
        {
            let p = mat.eval(*uv);
            for v in [p.kd.x, p.kd.y, p.kd.z, p.ks.x, p.ks.y, p.ks.z, p.alpha] {
                h.update(&v.to_le_bytes());
            }
        }
    }
    h.finalize().to_hex().to_string()
}
