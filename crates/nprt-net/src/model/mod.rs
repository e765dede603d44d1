//! A trained model as it is described and stored: its config, its folder and its layer table.

pub mod config;
pub mod direct_light;
pub mod folder;
pub mod layer_table;
