//! A complete static scene: meshes, materials, its own camera, volume and lighting.

use glam::Vec3;

use crate::camera::{Camera, CameraVolume};
use crate::envmap::EnvMap;
use crate::material::Material;
use crate::mesh::Mesh;

/// Mitsuba's default Russian-roulette start depth.
pub const DEFAULT_RR_DEPTH: u32 = 5;

/// The farthest a vertex may lie from the origin, in scene units on any axis: beyond it f32
/// positions keep no detail below about 100 units, and the BVH builder failed (an index out
/// of bounds at 10¹⁹, an endless loop at 10³⁰).
pub const MAX_COORDINATE: f32 = 1e9;

#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    /// The scene's own sensor and film, when the format has one.
    pub camera: Option<Camera>,
    /// Where dataset cameras may be placed; built-in scenes carry one.
    pub camera_volume: Option<CameraVolume>,
    pub envmap: Option<EnvMap>,
    /// The integrator's `max_depth` (Mitsuba's meaning); `None` means unlimited.
    pub max_depth: Option<u32>,
    pub rr_depth: u32,
    /// The scene's own sample count, when it names one.
    pub spp: Option<u32>,
    /// Approximations made while loading (e.g. a Beckmann lobe traced as GGX), for the user.
    pub warnings: Vec<String>,
}

impl Scene {
    pub fn empty(name: &str) -> Self {
        Scene {
            name: name.to_string(),
            meshes: vec![],
            materials: vec![],
            camera: None,
            camera_volume: None,
            envmap: None,
            max_depth: None,
            rr_depth: DEFAULT_RR_DEPTH,
            spp: None,
            warnings: vec![],
        }
    }

    /// Adds a mesh with its own material; returns the mesh index.
    pub fn add(&mut self, mut mesh: Mesh, material: Material) -> usize {
        mesh.material = self.materials.len();
        self.materials.push(material);
        self.meshes.push(mesh);
        self.meshes.len() - 1
    }

    /// Refuses geometry the tracer cannot hold: a vertex (after its shape's transform) not
    /// finite or beyond ±[`MAX_COORDINATE`] of the origin, naming the mesh. `what` names the
    /// scene in the error.
    pub fn check_extent(&self, what: &str) -> anyhow::Result<()> {
        for mesh in &self.meshes {
            let far = mesh
                .positions
                .iter()
                .find(|p| !p.is_finite() || p.abs().max_element() > MAX_COORDINATE);
            if let Some(p) = far {
                anyhow::bail!(
                    "{what}: mesh '{}' has a vertex at {p} (after its transform), beyond ±{MAX_COORDINATE:e} scene units of the origin: f32 positions there keep no detail below about 100 units, and the BVH cannot be built over them",
                    mesh.name
                );
            }
        }
        Ok(())
    }

    /// Axis-aligned bounds of all geometry (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for p in self.meshes.iter().flat_map(|m| &m.positions) {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        (lo, hi)
    }

    /// A camera for scenes that bring none: looking at the bounds' centre along −Z from far
    /// enough that their bounding sphere fills a 45° view, 512×512.
    pub fn framing_camera(&self) -> Camera {
        let (lo, hi) = self.bounds();
        let centre = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-3);
        let fov = 45.0f32;
        let distance = radius / (fov.to_radians() * 0.5).sin();
        Camera::look_at(
            centre + Vec3::new(0.0, 0.0, distance),
            centre,
            Vec3::Y,
            fov,
            512,
            512,
        )
    }

    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.indices.len()).sum()
    }
}
