//! Scene description for nprt: everything a renderer needs to know about a static scene and
//! its distant lighting, and the file formats they come from.
//!
//! This crate owns geometry (triangle meshes in world space), materials (the DESIGN.md model:
//! diffuse `kd`, GGX specular `ks`, GGX `alpha`, with textures), cameras, environment maps
//! (lat-long, Mitsuba 3's mapping, importance sampling, the spherical-harmonics basis) and the procedural built-in content, plus
//! the loaders for glTF 2.0, Mitsuba 3 XML, PLY and OBJ. It must not trace rays, sample paths or
//! know about datasets and networks: those belong to `nprt-trace` and later stages.
//!
//! ```
//! use nprt_scene::{load_scene, open_envmap, SceneOptions};
//!
//! let scene = load_scene("builtin:room", &SceneOptions::default())?;
//! let sky = open_envmap("builtin:sky:30:120")?;
//! assert!(scene.triangle_count() > 0 && scene.camera_volume.is_some());
//! assert!(sky.mean_radiance().max_element() > 0.0);
//! # Ok::<(), anyhow::Error>(())
//! ```

pub mod builtin;
mod bump_map;
mod camera;
mod color;
mod conductor_ior;
mod distribution;
pub mod envmap;
mod envmap_spec;
mod fresnel;
mod gltf_scene;
mod load_scene;
mod material;
mod mesh;
mod mesh_io;
pub mod mitsuba;
mod procedural;
mod scene;
mod scene_options;
pub mod spherical_harmonics;
mod texture;

pub use bump_map::BumpMap;
pub use camera::{Camera, CameraVolume, FovAxis};
pub use color::luminance;
pub use conductor_ior::{conductor_names, named_conductor};
pub use distribution::Distribution2D;
pub use envmap::EnvMap;
pub use envmap_spec::open_envmap;
pub use fresnel::{fresnel_conductor, fresnel_dielectric, DielectricFresnel};
pub use load_scene::load_scene;
pub use material::{BsdfParams, Material, Scattering, Surface, MIN_ALPHA};
pub use mesh::Mesh;
pub use scene::{Scene, MAX_COORDINATE};
pub use scene_options::SceneOptions;
pub use texture::{Bitmap, Texture};
