//! Helpers of the tests of the tracer on the device.
#![allow(dead_code, unused_imports)] // each test file uses its own subset

pub mod features_scene;
pub mod frame_noise;
pub mod shared_data;

pub use shared_data::shared;
