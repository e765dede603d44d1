//! Triangle meshes from PLY (ASCII or binary) and Wavefront OBJ files.

use std::path::Path;

use anyhow::{bail, Context, Result};
use glam::{Vec2, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use crate::mesh::Mesh;

/// Loads a .ply or .obj mesh; vertex normals are computed when the file has none, unless
/// `face_normals` asks for flat shading (Mitsuba's `face_normals`).
pub fn load_mesh(path: &Path, face_normals: bool) -> Result<Mesh> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let mut mesh = match ext.as_str() {
        "ply" => load_ply(path),
        "obj" => load_obj(path),
        _ => bail!("unsupported mesh format '.{ext}' (expected .ply or .obj)"),
    }
    .with_context(|| format!("cannot load mesh '{}'", path.display()))?;
    mesh.name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    mesh.validate(&path.display().to_string())?;
    if face_normals {
        mesh.normals.clear();
    } else if mesh.normals.is_empty() {
        mesh.compute_vertex_normals();
    }
    Ok(mesh)
}

fn scalar(e: &DefaultElement, names: &[&str]) -> Option<f32> {
    names
        .iter()
        .find_map(|n| e.get(*n))
        .and_then(Property::to_f32_lossy)
}

fn index_list(p: &Property) -> Option<Vec<u32>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&i| i as u32).collect(),
        Property::ListUChar(v) => v.iter().map(|&i| i as u32).collect(),
        Property::ListShort(v) => v.iter().map(|&i| i as u32).collect(),
        Property::ListUShort(v) => v.iter().map(|&i| i as u32).collect(),
        Property::ListInt(v) => v.iter().map(|&i| i as u32).collect(),
        Property::ListUInt(v) => v.clone(),
        _ => return None,
    })
}

/// Fans a polygon into triangles.
fn fan(poly: &[u32], out: &mut Vec<[u32; 3]>) {
    for k in 1..poly.len().saturating_sub(1) {
        out.push([poly[0], poly[k], poly[k + 1]]);
    }
}

fn load_ply(path: &Path) -> Result<Mesh> {
    nprt_io::check_input(path)?;
    let mut file = std::io::BufReader::new(std::fs::File::open(path)?);
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut file)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let vertices = ply.payload.get("vertex").context("no 'vertex' element")?;
    let faces = ply.payload.get("face").context("no 'face' element")?;
    let mut mesh = Mesh::default();
    for v in vertices {
        let p = (scalar(v, &["x"]), scalar(v, &["y"]), scalar(v, &["z"]));
        let (Some(x), Some(y), Some(z)) = p else {
            bail!("a vertex lacks x, y or z")
        };
        mesh.positions.push(Vec3::new(x, y, z));
        if let (Some(nx), Some(ny), Some(nz)) =
            (scalar(v, &["nx"]), scalar(v, &["ny"]), scalar(v, &["nz"]))
        {
            mesh.normals.push(Vec3::new(nx, ny, nz).normalize_or_zero());
        }
        if let (Some(u), Some(t)) = (
            scalar(v, &["u", "s", "texture_u"]),
            scalar(v, &["v", "t", "texture_v"]),
        ) {
            mesh.uvs.push(Vec2::new(u, t));
        }
    }
    for f in faces {
        let list = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .context("a face lacks vertex_indices")?;
        fan(
            &index_list(list).context("face indices are not an integer list")?,
            &mut mesh.indices,
        );
    }
    Ok(mesh)
}

fn load_obj(path: &Path) -> Result<Mesh> {
    let opts = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _) = tobj::load_obj(path, &opts)?;
    let mut mesh = Mesh::default();
    for m in models {
        let src = m.mesh;
        let base = mesh.positions.len() as u32;
        let n = src.positions.len() / 3;
        mesh.positions
            .extend(src.positions.chunks(3).map(|p| Vec3::new(p[0], p[1], p[2])));
        if src.normals.len() == 3 * n {
            mesh.normals.extend(
                src.normals
                    .chunks(3)
                    .map(|p| Vec3::new(p[0], p[1], p[2]).normalize_or_zero()),
            );
        }
        if src.texcoords.len() == 2 * n {
            // OBJ's v runs upwards; Mitsuba flips it so images are not upside down.
            mesh.uvs
                .extend(src.texcoords.chunks(2).map(|t| Vec2::new(t[0], 1.0 - t[1])));
        }
        mesh.indices.extend(
            src.indices
                .chunks(3)
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }
    if mesh.normals.len() != mesh.positions.len() {
        mesh.normals.clear();
    }
    if mesh.uvs.len() != mesh.positions.len() {
        mesh.uvs.clear();
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_ply_quad_and_obj_agree() {
        let dir = std::env::temp_dir().join(format!("nprt-meshio-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let ply = dir.join("quad.ply");
        std::fs::write(
            &ply,
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
             element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n",
        )
        .unwrap();
        let obj = dir.join("quad.obj");
        std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
        for path in [ply, obj] {
            let m = load_mesh(&path, false).unwrap();
            assert_eq!(m.indices.len(), 2, "{}", path.display());
            assert!((m.area() - 1.0).abs() < 1e-6);
            assert!(m.normals.iter().all(|n| (*n - Vec3::Z).length() < 1e-6));
        }
        let err = load_mesh(&dir.join("missing.ply"), false).unwrap_err();
        assert!(format!("{err:#}").contains("missing.ply"), "{err:#}");
    }
}
