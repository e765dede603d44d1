//! Built-in environment maps, for when no map files are given: an outdoor sky with sun from the
//! Preetham et al. 1999 analytic daylight model, and an indoor-style generator (bright window
//! and lamp regions over a dim surround). Every choice is driven by explicit parameters or a seed.

mod indoor;
mod sky;

pub use indoor::indoor;
pub use sky::{sky, SkyParams};
