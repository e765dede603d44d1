//! A scene's triangles, materials and textures on the GPU, uploaded once, with a BVH over its
//! triangles, built and uploaded when the path tracer first needs it: what the rasterised
//! G-buffer and the path tracer read. The records' layouts are
//! the contract with `shaders/surface.wgsl` and `shaders/bsdf.wgsl`, which evaluate them as
//! nprt-trace's `surface_point` and `Bsdf` and nprt-scene's materials do on the CPU.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use anyhow::{Context, Result};
use glam::Vec3;
use nprt_gpu::GpuDevice;
use nprt_scene::{BsdfParams, Material, Scattering, Surface, Texture};

use crate::{Coating, FlatBvh, TraceScene};

/// Words per material record (see [`material_record`]).
pub const MATERIAL_WORDS: usize = 32;
/// Words per texture record (see [`texture_record`]).
pub const TEXTURE_WORDS: usize = 16;

/// Material flags, as `shaders/surface.wgsl` reads them.
const TWO_SIDED: u32 = 1;
const BUMP: u32 = 2;
const BUMP_MIRRORED_BEHIND: u32 = 4;
const OPACITY: u32 = 8;
const METALLIC_ROUGHNESS: u32 = 16;

/// Scattering kinds and their flags, as `shaders/bsdf.wgsl` reads them.
const FRESNEL_FREE: u32 = 0;
const CONDUCTOR: u32 = 1;
const DIELECTRIC: u32 = 2;
const PLASTIC: u32 = 3;
const THIN: u32 = 1;
const NONLINEAR: u32 = 2;

/// Per-vertex attribute flags of a mesh.
const HAS_NORMALS: u32 = 1;
const HAS_UVS: u32 = 2;

/// The BVH's nodes and its leaves' triangles ([`FlatBvh`]) on the device.
pub struct GpuBvh {
    pub nodes: wgpu::Buffer,
    pub triangles: wgpu::Buffer,
}

/// The scene on the device.
pub struct GpuScene {
    /// Every mesh's vertex positions, 3 f32 each, meshes one after another.
    pub positions: wgpu::Buffer,
    /// Per vertex: shading normal (3) and uv (2); zero where the mesh has none.
    pub attributes: wgpu::Buffer,
    /// Per triangle: three vertex indices into `positions` and its mesh's flags and material
    /// packed as `flags | material << 2`.
    pub triangles: wgpu::Buffer,
    pub materials: wgpu::Buffer,
    pub textures: wgpu::Buffer,
    /// Every bitmap's texels, 3 f32 each, top row first.
    pub bitmaps: wgpu::Buffer,
    /// The BVH, made at its first use: a model that never traces (and the rasteriser) does not
    /// wait for it (0.76 s for the KITCHEN's 1.05 M triangles).
    bvh: OnceLock<GpuBvh>,
    /// What the BVH is made from until then: the vertex positions and `triangles`' words.
    unbuilt: Mutex<Option<(Vec<f32>, Vec<u32>)>>,
    pub triangle_count: u32,
    /// The scene's extent (the bounding box's diagonal), for the rasteriser's near plane.
    pub extent: f32,
}

impl GpuScene {
    /// Uploads `ts`'s scene; refuses one whose triangles or textures a GPU buffer cannot hold.
    pub fn new(gpu: &GpuDevice, ts: &TraceScene) -> Result<Self> {
        let scene = &*ts.scene;
        let vertices: usize = scene.meshes.iter().map(|m| m.positions.len()).sum();
        let mut positions = Vec::with_capacity(3 * vertices);
        let mut attributes = Vec::with_capacity(5 * vertices);
        let mut triangles: Vec<u32> = Vec::with_capacity(4 * scene.triangle_count());
        for mesh in &scene.meshes {
            let first = (positions.len() / 3) as u32;
            let flags = if mesh.normals.is_empty() {
                0
            } else {
                HAS_NORMALS
            } | if mesh.uvs.is_empty() { 0 } else { HAS_UVS };
            for (i, p) in mesh.positions.iter().enumerate() {
                positions.extend_from_slice(&p.to_array());
                let n = mesh.normals.get(i).copied().unwrap_or(Vec3::ZERO);
                let uv = mesh.uvs.get(i).copied().unwrap_or_default();
                attributes.extend_from_slice(&[n.x, n.y, n.z, uv.x, uv.y]);
            }
            for tri in &mesh.indices {
                triangles.extend(tri.map(|i| first + i));
                triangles.push(flags | (mesh.material as u32) << 2);
            }
        }
        let mut bitmaps = TexelStore::default();
        let mut textures = Vec::new();
        let mut materials: Vec<u32> = scene
            .materials
            .iter()
            .flat_map(|m| material_record(m, &mut textures, &mut bitmaps))
            .collect();
        // The plastics' coats after the records, each record pointing at its own.
        for (m, coat) in ts.coatings.iter().enumerate() {
            if let Some(coat) = coat {
                let at = materials.len() as u32;
                materials[MATERIAL_WORDS * m + 21] = at;
                materials.extend(coat_record(coat));
            }
        }
        // The BVH's sizes at most: a binary tree over n triangles has fewer than 2n nodes.
        let count = scene.triangle_count();
        for (words, what) in [
            (positions.len(), "the scene's vertex positions"),
            (attributes.len(), "the scene's vertex normals and uvs"),
            (triangles.len(), "the scene's triangles"),
            (bitmaps.texels.len(), "the scene's textures"),
            (2 * count.max(1) * crate::NODE_WORDS, "the scene's BVH"),
            (
                count * crate::TRIANGLE_WORDS,
                "the scene's triangles in BVH order",
            ),
        ] {
            gpu.check_binding(4 * words, &format!("{what} ('{}')", scene.name))
                .context("the GPU frame path cannot take the scene; use --device cpu")?;
        }
        let (lo, hi) = scene.bounds();
        Ok(GpuScene {
            positions: gpu.upload(&positions),
            attributes: gpu.upload(&attributes),
            triangles: gpu.upload(&triangles),
            materials: gpu.upload(&materials),
            textures: gpu.upload(&textures),
            bitmaps: gpu.upload(&bitmaps.texels),
            bvh: OnceLock::new(),
            unbuilt: Mutex::new(Some((positions, triangles))),
            triangle_count: count as u32,
            extent: (hi - lo).length(),
        })
    }

    /// The BVH on the device, built and uploaded on the first call.
    pub fn bvh(&self, gpu: &GpuDevice) -> &GpuBvh {
        self.bvh.get_or_init(|| {
            let taken = self
                .unbuilt
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .take();
            let (positions, triangles) = taken.expect("the BVH's triangles, kept until it is made");
            let corner = |i: u32| Vec3::from_slice(&positions[3 * i as usize..]);
            let corners = triangles
                .chunks_exact(4)
                .map(|t| [t[0], t[1], t[2]].map(corner));
            let bvh = FlatBvh::from_corners(corners);
            GpuBvh {
                nodes: gpu.upload(&bvh.nodes),
                // A buffer may not be empty.
                triangles: gpu.upload(if bvh.triangles.is_empty() {
                    &[0; crate::TRIANGLE_WORDS]
                } else {
                    &bvh.triangles
                }),
            }
        })
    }

    /// Whether [`Self::bvh`] was made.
    pub fn has_bvh(&self) -> bool {
        self.bvh.get().is_some()
    }
}

/// Bitmaps' texels laid end to end, each bitmap once however many textures share it.
#[derive(Default)]
struct TexelStore {
    texels: Vec<f32>,
    offsets: HashMap<*const nprt_scene::Bitmap, u32>,
}

impl TexelStore {
    /// The offset (in texels) of `bitmap`, stored on first sight.
    fn offset(&mut self, bitmap: &Arc<nprt_scene::Bitmap>) -> u32 {
        *self.offsets.entry(Arc::as_ptr(bitmap)).or_insert_with(|| {
            let at = (self.texels.len() / 3) as u32;
            self.texels
                .extend(bitmap.texels.iter().flat_map(|t| t.to_array()));
            at
        })
    }
}

/// A material's record: `[flags, texture ids (kd, ks, α) or (base, metallic-roughness, —),
/// opacity texture, bump texture, bump scale, ks's factor at normal incidence (3), scattering
/// kind, its flags, η (glass, plastic), the plastic's specular sampling weight, the conductor's
/// η (3) and k (3), kt's texture, the coat's offset (see [`coat_record`]; 0: none), 0…]`. Its
/// textures are appended to `textures`.
fn material_record(
    m: &Material,
    textures: &mut Vec<u32>,
    bitmaps: &mut TexelStore,
) -> [u32; MATERIAL_WORDS] {
    let mut add = |t: &Texture| {
        let id = (textures.len() / TEXTURE_WORDS) as u32;
        textures.extend(texture_record(t, bitmaps));
        id
    };
    let mut flags = if m.two_sided { TWO_SIDED } else { 0 };
    let ids = match &m.surface {
        Surface::Direct { kd, ks, alpha } => [add(kd), add(ks), add(alpha)],
        Surface::MetallicRoughness {
            base,
            metallic_roughness,
        } => {
            flags |= METALLIC_ROUGHNESS;
            [add(base), add(metallic_roughness), 0]
        }
    };
    let opacity = m.opacity.as_ref().map_or(0, |o| {
        flags |= OPACITY;
        add(o)
    });
    let (bump, scale) = m.bump.as_ref().map_or((0, 0.0), |b| {
        flags |= BUMP;
        if b.mirrored_behind {
            flags |= BUMP_MIRRORED_BEHIND;
        }
        (add(&b.height), b.scale)
    });
    // The G-buffer's ks is at normal incidence: the scattering's Fresnel factor there.
    let fresnel = BsdfParams {
        scattering: m.scattering,
        ..BsdfParams::new(Vec3::ZERO, Vec3::ONE, 1.0)
    }
    .normal_incidence_ks();
    let mut r = [0u32; MATERIAL_WORDS];
    r[..7].copy_from_slice(&[
        flags,
        ids[0],
        ids[1],
        ids[2],
        opacity,
        bump,
        scale.to_bits(),
    ]);
    r[7..10].copy_from_slice(&fresnel.to_array().map(f32::to_bits));
    let (kind, scatter_flags, eta, weight, conductor) = match m.scattering {
        Scattering::FresnelFree => (FRESNEL_FREE, 0, 1.0, 0.0, [Vec3::ZERO; 2]),
        Scattering::Conductor { eta, k } => (CONDUCTOR, 0, 1.0, 0.0, [eta, k]),
        Scattering::Dielectric { eta, thin } => (
            DIELECTRIC,
            if thin { THIN } else { 0 },
            eta,
            0.0,
            [Vec3::ZERO; 2],
        ),
        Scattering::Plastic {
            eta,
            nonlinear,
            sampling_weight,
            ..
        } => (
            PLASTIC,
            if nonlinear { NONLINEAR } else { 0 },
            eta,
            sampling_weight,
            [Vec3::ZERO; 2],
        ),
    };
    r[10..14].copy_from_slice(&[kind, scatter_flags, eta.to_bits(), weight.to_bits()]);
    for (k, v) in conductor.iter().enumerate() {
        r[14 + 3 * k..17 + 3 * k].copy_from_slice(&v.to_array().map(f32::to_bits));
    }
    r[20] = add(&m.transmittance);
    r
}

/// Words per coat record.
const COAT_WORDS: usize = 66;

/// A plastic's coat: `[the base's internal reflectance, rough (1) or smooth (0), the rough
/// coat's transmittance table (64)]`.
fn coat_record(coat: &Coating) -> [u32; COAT_WORDS] {
    let mut r = [0u32; COAT_WORDS];
    r[0] = coat.internal_reflectance.to_bits();
    if let Some(table) = coat.table() {
        r[1] = 1;
        for (w, t) in r[2..].iter_mut().zip(table) {
            *w = t.to_bits();
        }
    }
    r
}

/// Texture kinds, as `shaders/gbuffer.wgsl` reads them.
const CONSTANT: u32 = 0;
const BITMAP: u32 = 1;
const CHECKERBOARD: u32 = 2;

/// A texture's record: `[kind, texel offset, width, height, colour (the constant, a bitmap's
/// factor or the checkerboard's color0) (3), color1 (3), uv transform (x axis, y axis,
/// translation: 6)]`.
fn texture_record(t: &Texture, bitmaps: &mut TexelStore) -> [u32; TEXTURE_WORDS] {
    let (kind, texels, size, colour, color1, to_uv) = match t {
        Texture::Constant(c) => (CONSTANT, 0, [0, 0], *c, Vec3::ZERO, glam::Affine2::IDENTITY),
        Texture::Bitmap {
            image,
            to_uv,
            factor,
        } => (
            BITMAP,
            bitmaps.offset(image),
            [image.width as u32, image.height as u32],
            *factor,
            Vec3::ZERO,
            *to_uv,
        ),
        Texture::Checkerboard {
            color0,
            color1,
            to_uv,
        } => (CHECKERBOARD, 0, [0, 0], *color0, *color1, *to_uv),
    };
    let mut r = [0u32; TEXTURE_WORDS];
    r[..4].copy_from_slice(&[kind, texels, size[0], size[1]]);
    let words: Vec<u32> = colour
        .to_array()
        .into_iter()
        .chain(color1.to_array())
        .chain(to_uv.matrix2.x_axis.to_array())
        .chain(to_uv.matrix2.y_axis.to_array())
        .chain(to_uv.translation.to_array())
        .map(f32::to_bits)
        .collect();
    r[4..].copy_from_slice(&words);
    r
}
