//! How the transport network sees a pixel's position: as the paper gives it (three normalised
//! coordinates) or through a learned multiresolution hash grid.

use crate::choice::named_choice;
use crate::encoding::hash_grid;

/// The input encoding of the position for every track of a design.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PositionEncoding {
    /// The paper: x, y, z in [−1, 1] and nothing else. Models saved before the choice existed
    /// were built this way.
    #[default]
    None,
    /// The three coordinates plus the features a multiresolution hash grid (Müller et al.
    /// 2022) stores at the position, learned with the network: per-place memory that a small
    /// MLP has to build from smooth functions of x otherwise ([`hash_grid`]).
    HashGrid,
}

named_choice!(PositionEncoding, "position encoding", {
    None => "none",
    HashGrid => "hash-grid",
});

impl PositionEncoding {
    pub fn is_none(&self) -> bool {
        *self == PositionEncoding::None
    }

    /// Inputs a track gets on top of the pixel inputs it reads.
    pub fn extra_inputs(self) -> usize {
        match self {
            PositionEncoding::None => 0,
            PositionEncoding::HashGrid => hash_grid::OUTPUTS,
        }
    }
}
