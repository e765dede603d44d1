//! glTF 2.0 (.gltf, .glb): meshes under their node transforms, metallic-roughness materials
//! and their textures (mapped as DESIGN.md says), and the first perspective camera.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use anyhow::{anyhow, bail, Context, Result};
use glam::{Affine2, Mat4, Vec2, Vec3};

use crate::camera::{Camera, FovAxis};
use crate::material::{Material, Surface};
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::texture::{Bitmap, Texture};
use nprt_io::linear_rgb;

pub fn load(path: &Path) -> Result<Scene> {
    let name = path.display().to_string();
    let bytes =
        nprt_io::read_input(path).with_context(|| format!("cannot read glTF file '{name}'"))?;
    // Required extensions are checked before validation, which would bury them in a list of
    // consequences (e.g. Draco-compressed accessors without buffer views).
    let unvalidated = gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| anyhow!("cannot read glTF file '{name}': {e}"))?;
    let required: Vec<&str> = unvalidated.document.extensions_required().collect();
    if !required.is_empty() {
        let what = if required.contains(&"KHR_draco_mesh_compression") {
            " (Draco mesh compression)"
        } else {
            ""
        };
        bail!(
            "glTF file '{name}' requires extension(s) {}{what}, which nprt does not support; re-export it without them",
            required.join(", ")
        );
    }
    let gltf =
        gltf::Gltf::from_slice(&bytes).map_err(|e| anyhow!("invalid glTF file '{name}': {e}"))?;
    let doc = &gltf.document;
    let base = path.parent();
    let buffers = gltf::import_buffers(doc, base, gltf.blob.clone())
        .map_err(|e| anyhow!("glTF file '{name}': cannot load its buffers: {e}"))?;
    let images = gltf::import_images(doc, base, &buffers)
        .map_err(|e| anyhow!("glTF file '{name}': cannot load its images: {e}"))?;

    let mut loader = Loader {
        name: &name,
        buffers,
        images,
        bitmaps: HashMap::new(),
        materials: HashMap::new(),
        scene: Scene::empty(&name),
    };
    let gscene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .with_context(|| format!("glTF file '{name}' has no scene"))?;
    for node in gscene.nodes() {
        loader.visit(&node, Mat4::IDENTITY)?;
    }
    Ok(loader.scene)
}

struct Loader<'a> {
    name: &'a str,
    buffers: Vec<gltf::buffer::Data>,
    images: Vec<gltf::image::Data>,
    /// (image index, sRGB) → decoded bitmap, shared between materials.
    bitmaps: HashMap<(usize, bool), Arc<Bitmap>>,
    /// glTF material index (None: the default material) → scene material index.
    materials: HashMap<Option<usize>, usize>,
    scene: Scene,
}

impl Loader<'_> {
    fn visit(&mut self, node: &gltf::Node, parent: Mat4) -> Result<()> {
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let what = format!(
                    "glTF file '{}', mesh '{}'",
                    self.name,
                    mesh.name().unwrap_or("?")
                );
                self.primitive(&prim, world, &what)?;
            }
        }
        if let (Some(cam), None) = (node.camera(), &self.scene.camera) {
            if let gltf::camera::Projection::Perspective(p) = cam.projection() {
                let aspect = p.aspect_ratio().unwrap_or(1.0);
                // glTF cameras look down -Z with +X right; ours look down +Z with +X left.
                let flip = Mat4::from_scale(Vec3::new(-1.0, 1.0, -1.0));
                self.scene.camera = Some(Camera {
                    to_world: world * flip,
                    fov_deg: p.yfov().to_degrees(),
                    fov_axis: FovAxis::Y,
                    width: 512,
                    height: (512.0 / aspect).round().max(1.0) as u32,
                });
            }
        }
        for child in node.children() {
            self.visit(&child, world)?;
        }
        Ok(())
    }

    fn primitive(&mut self, prim: &gltf::Primitive, world: Mat4, what: &str) -> Result<()> {
        if prim.mode() != gltf::mesh::Mode::Triangles {
            bail!(
                "{what}: primitive mode {:?} is not supported (only triangles)",
                prim.mode()
            );
        }
        let reader = prim.reader(|b| self.buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .with_context(|| format!("{what}: primitive has no POSITION"))?
            .map(Vec3::from)
            .collect();
        let n = positions.len() as u32;
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..n).collect(),
        };
        let mut mesh = Mesh {
            name: what.to_string(),
            normals: reader
                .read_normals()
                .map(|r| r.map(Vec3::from).collect())
                .unwrap_or_default(),
            uvs: reader
                .read_tex_coords(0)
                .map(|r| r.into_f32().map(Vec2::from).collect())
                .unwrap_or_default(),
            indices: indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
            positions,
            material: 0,
        };
        mesh.validate(what)?;
        if mesh.normals.is_empty() {
            mesh.compute_vertex_normals();
        }
        mesh.transform(world);
        // A mirroring transform turns counter-clockwise faces clockwise; shading normals were
        // already carried over correctly by the inverse transpose.
        if world.determinant() < 0.0 {
            mesh.reverse_winding();
        }
        mesh.material = self.material(prim.material())?;
        self.scene.meshes.push(mesh);
        Ok(())
    }

    fn material(&mut self, m: gltf::Material) -> Result<usize> {
        if let Some(&i) = self.materials.get(&m.index()) {
            return Ok(i);
        }
        let label = format!(
            "glTF file '{}', material '{}'",
            self.name,
            m.name().unwrap_or("default")
        );
        if m.normal_texture().is_some() {
            self.scene.warnings.push(format!(
                "{label}: its normal map is ignored (shading uses vertex normals)"
            ));
        }
        if m.emissive_factor() != [0.0; 3] || m.emissive_texture().is_some() {
            self.scene.warnings.push(format!(
                "{label}: emission is ignored (light comes from the environment only)"
            ));
        }
        if m.alpha_mode() != gltf::material::AlphaMode::Opaque {
            self.scene.warnings.push(format!(
                "{label}: alpha mode {:?} is traced as opaque",
                m.alpha_mode()
            ));
        }
        let pbr = m.pbr_metallic_roughness();
        let bc = pbr.base_color_factor();
        let base_factor = Vec3::new(bc[0], bc[1], bc[2]);
        let mr_factor = Vec3::new(1.0, pbr.roughness_factor(), pbr.metallic_factor());
        let base = match pbr.base_color_texture() {
            Some(info) => self.texture(&info, true, base_factor)?,
            None => Texture::Constant(base_factor),
        };
        let metallic_roughness = match pbr.metallic_roughness_texture() {
            Some(info) => self.texture(&info, false, mr_factor)?,
            None => Texture::Constant(mr_factor),
        };
        let material = Material::new(
            m.name().unwrap_or("default"),
            Surface::MetallicRoughness {
                base,
                metallic_roughness,
            },
            m.double_sided(),
        );
        self.scene.materials.push(material);
        let idx = self.scene.materials.len() - 1;
        self.materials.insert(m.index(), idx);
        Ok(idx)
    }

    fn texture(&mut self, info: &gltf::texture::Info, srgb: bool, factor: Vec3) -> Result<Texture> {
        if info.tex_coord() != 0 {
            bail!(
                "glTF file '{}': textures on TEXCOORD_{} are not supported",
                self.name,
                info.tex_coord()
            );
        }
        let index = info.texture().source().index();
        let image = match self.bitmaps.get(&(index, srgb)) {
            Some(b) => b.clone(),
            None => {
                let data = &self.images[index];
                let bitmap = Arc::new(
                    bitmap_from_gltf(data, srgb)
                        .with_context(|| format!("glTF file '{}', image {index}", self.name))?,
                );
                self.bitmaps.insert((index, srgb), bitmap.clone());
                bitmap
            }
        };
        Ok(Texture::Bitmap {
            image,
            to_uv: Affine2::IDENTITY,
            factor,
        })
    }
}

fn bitmap_from_gltf(data: &gltf::image::Data, srgb: bool) -> Result<Bitmap> {
    use gltf::image::Format;
    let (w, h) = (data.width, data.height);
    let channels = match data.format {
        Format::R8 => 1,
        Format::R8G8 => 2,
        Format::R8G8B8 => 3,
        Format::R8G8B8A8 => 4,
        f => bail!("pixel format {f:?} is not supported"),
    };
    let buf: image::RgbImage = image::ImageBuffer::from_fn(w, h, |x, y| {
        let i = ((y * w + x) as usize) * channels;
        let p = &data.pixels[i..i + channels];
        match channels {
            1 | 2 => image::Rgb([p[0]; 3]),
            _ => image::Rgb([p[0], p[1], p[2]]),
        }
    });
    Ok(Bitmap::from(linear_rgb(
        image::DynamicImage::ImageRgb8(buf),
        !srgb,
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;
    use std::path::PathBuf;

    /// A textured quad under a translated, scaled node, plus a camera node, written as a
    /// .gltf with its buffer and textures as separate files.
    fn write_quad(dir: &Path) -> PathBuf {
        std::fs::create_dir_all(dir).unwrap();
        let pos: [[f32; 3]; 4] = [[-1., -1., 0.], [1., -1., 0.], [1., 1., 0.], [-1., 1., 0.]];
        let uv: [[f32; 2]; 4] = [[0., 1.], [1., 1.], [1., 0.], [0., 0.]];
        let idx: [u16; 6] = [0, 1, 2, 0, 2, 3];
        let mut bin = vec![];
        pos.iter()
            .flatten()
            .for_each(|v| bin.extend(v.to_le_bytes()));
        uv.iter()
            .flatten()
            .for_each(|v| bin.extend(v.to_le_bytes()));
        idx.iter().for_each(|v| bin.extend(v.to_le_bytes()));
        std::fs::write(dir.join("quad.bin"), &bin).unwrap();
        // Base colour: left half sRGB 255 red, right half sRGB 128 grey. Metal-rough: G = 128 (roughness), B = 255 (metal) on the right.
        let base = image::RgbImage::from_fn(2, 1, |x, _| {
            if x == 0 {
                image::Rgb([255, 0, 0])
            } else {
                image::Rgb([128, 128, 128])
            }
        });
        base.save(dir.join("base.png")).unwrap();
        let mr = image::RgbImage::from_fn(2, 1, |x, _| {
            if x == 0 {
                image::Rgb([0, 128, 0])
            } else {
                image::Rgb([0, 128, 255])
            }
        });
        mr.save(dir.join("mr.png")).unwrap();
        let json = serde_json::json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0, 1]}],
            "nodes": [
                {"mesh": 0, "translation": [0.0, 2.0, 0.0], "scale": [3.0, 3.0, 3.0]},
                {"camera": 0, "translation": [0.0, 2.0, 10.0]}
            ],
            "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1, "aspectRatio": 2.0}}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
            "materials": [{"pbrMetallicRoughness": {
                "baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 1},
                "metallicFactor": 1.0, "roughnessFactor": 1.0}, "doubleSided": true}],
            "textures": [{"source": 0}, {"source": 1}],
            "images": [{"uri": "base.png"}, {"uri": "mr.png"}],
            "buffers": [{"uri": "quad.bin", "byteLength": bin.len()}],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": 48},
                {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                {"buffer": 0, "byteOffset": 80, "byteLength": 12}
            ],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
                {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}
            ]
        });
        let path = dir.join("quad.gltf");
        std::fs::write(&path, serde_json::to_string_pretty(&json).unwrap()).unwrap();
        path
    }

    #[test]
    fn loads_nodes_materials_textures_and_camera() {
        let dir = std::env::temp_dir().join(format!("nprt-gltf-{}", std::process::id()));
        let s = load(&write_quad(&dir)).unwrap();
        assert_eq!(s.triangle_count(), 2);
        let (lo, hi) = s.bounds();
        assert!(
            (lo - Vec3::new(-3.0, -1.0, 0.0)).length() < 1e-5
                && (hi - Vec3::new(3.0, 5.0, 0.0)).length() < 1e-5
        );
        let m = &s.materials[s.meshes[0].material];
        assert!(m.two_sided);
        // Left texel: dielectric red, α = (128/255)².
        let left = m.eval(Vec2::new(0.25, 0.5));
        assert!(
            (left.kd - Vec3::new(1.0, 0.0, 0.0)).length() < 1e-4,
            "{:?}",
            left
        );
        assert!((left.ks - Vec3::splat(0.04)).length() < 1e-4);
        assert!((left.alpha - (128.0f32 / 255.0).powi(2)).abs() < 1e-4);
        // Right texel: metal, so no diffuse and ks = linear(128/255) ≈ 0.2158.
        let right = m.eval(Vec2::new(0.75, 0.5));
        assert!(
            right.kd.length() < 1e-4 && (right.ks.x - 0.2158).abs() < 1e-3,
            "{:?}",
            right
        );
        let cam = s.camera.as_ref().unwrap();
        assert_eq!((cam.width, cam.height), (512, 256));
        assert!((cam.origin() - Vec3::new(0.0, 2.0, 10.0)).length() < 1e-5);
        // glTF cameras look down −Z: the centre ray hits the quad's centre.
        let (_, d) = cam.ray(Vec2::new(256.0, 128.0));
        assert!((d - -Vec3::Z).length() < 1e-5, "{d}");
    }
}
