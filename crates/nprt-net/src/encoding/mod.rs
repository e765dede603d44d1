//! What the networks see: a pixel's G-buffer features, the position encodings beyond the
//! paper's (a hash grid), the SH basis, and how a map is normalised for the encoder.

pub mod features;
pub mod hash_grid;
pub mod map_norm;
pub mod position_encoding;
/// The SH basis lives with the lighting it describes (nprt-scene), where the dataset
/// generator records transport on it too.
pub use nprt_scene::spherical_harmonics;
