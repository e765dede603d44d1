//! Dataset generation for training: where cameras go, which lighting each view gets, and how
//! views are stored. It owns placement and dataset bookkeeping, and renders only through
//! `nprt-trace`; it must not parse scene files, trace paths itself or know about networks.
//!
//! So far: camera placement in a scene's active volume (see [`cameras`]).

pub mod cameras;

pub use cameras::{place_camera, PlacementError};
