//! Dataset generation for training: where cameras go, which lighting each view gets, and how
//! views are stored and verified. It owns placement and dataset bookkeeping, and renders only
//! through `nprt-trace`; it must not parse scene files, trace paths itself or know about
//! networks.
//!
//! ```
//! use nprt_data::dataset::{self, Request};
//! use nprt_scene::{load_scene, open_envmap, SceneOptions};
//! use nprt_trace::{TraceScene, Tracer};
//!
//! let scene = load_scene("builtin:room", &SceneOptions::default())?;
//! let map_specs = vec!["builtin:sky".to_string(), "builtin:indoor:1".to_string()];
//! let maps = map_specs.iter().map(|s| open_envmap(s)).collect::<anyhow::Result<Vec<_>>>()?;
//! let ts = TraceScene::new(&scene);
//! let request = Request {
//!     scene_spec: "builtin:room".into(),
//!     scene: &scene,
//!     scene_source: dataset::scene_source("builtin:room")?,
//!     volume: scene.camera_volume.clone().unwrap(),
//!     map_specs,
//!     maps,
//!     lighting: dataset::MapAssignment::Pool { test_maps: 1, builtin_share: 0.0 },
//!     views: dataset::ViewSpec {
//!         train_views: 2,
//!         test_views: 1,
//!         train_resolution: [8, 8],
//!         test_resolution: [8, 8],
//!         spp: 2,
//!         test_spp: 4,
//!         seed: 0,
//!         jitter: dataset::Jitter::default(),
//!         mix_maps: 1,
//!     },
//! };
//! let manifest = dataset::plan(&request, &ts)?;
//! let dir = std::env::temp_dir().join(format!("nprt-data-doc-{}", std::process::id()));
//! dataset::prepare(&dir, &manifest)?;
//! dataset::run(&Tracer::Cpu(&ts), &request.maps, &manifest, &dir, (0, 1), false)?;
//! assert_eq!(dataset::verify(&dir)?.complete, 3);
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), anyhow::Error>(())
//! ```

mod camera_choice;
pub mod cameras;
pub mod dataset;
mod generate;
pub mod lighting;
mod shard;
pub mod views;

pub use camera_choice::CameraChoice;
pub use cameras::{place_camera, PlacementError};
pub use dataset::{Manifest, Request, ViewSpec};
pub use generate::{generate, GenerateOptions, Planned};
pub use shard::shard_from_env;
