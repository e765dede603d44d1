//! What the networks see: a pixel's G-buffer features, the position encodings beyond the
//! paper's (a hash grid), the SH basis, and how a map is normalised for the encoder.

pub mod features;
pub mod hash_grid;
pub mod map_norm;
pub mod position_encoding;
pub mod spherical_harmonics;
