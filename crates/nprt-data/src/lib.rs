//! Dataset generation for training: where cameras go, which lighting each view gets, and how
//! views are stored and verified. It owns placement and dataset bookkeeping, and renders only
//! through `nprt-trace`; it must not parse scene files, trace paths itself or know about
//! networks.

pub mod cameras;
pub mod dataset;
pub mod lighting;
pub mod views;

pub use cameras::{place_camera, PlacementError};
pub use dataset::{Manifest, Request};
