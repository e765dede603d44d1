//! Where the lighting enters a track: the one fact about a track's sequence that every engine
//! needs besides its networks. It decides what a lighting change runs (everything from the
//! entry on) and what a still camera keeps (everything before it), and how the shading
//! network's first layer is laid out; the CPU engine, the GPU frame path and trainer and the
//! shader export read it from here instead of restating it from the design.

use std::ops::Range;

use crate::network::encoder::CODE_SIZE;

/// Where a track's shading network Φ meets the light code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightEntry {
    /// Φ's first layer reads the encoder's code ê beside its per-row input: ê multiplies its
    /// weight rows from `code_row` (CODE_SIZE of them), the per-row input those from
    /// `own_row`. A lighting folds ê's share into that layer's bias; a still camera keeps Φ's
    /// per-row input (ŝ, or the baseline's inputs).
    FirstLayer { code_row: usize, own_row: usize },
    /// Φ reads its per-row input alone and outputs K transfer coefficients per term and
    /// channel, each term their dot product with the light code (a basis projection) at the
    /// combine: a still camera keeps Φ's outputs, and a lighting runs only the combine.
    Combine { k: usize },
}

impl LightEntry {
    /// The paper's: ê after ŝ ([ŝ, ê]) behind a transfer network, else first ([ê, inputs]).
    pub fn first_layer(after_transfer: bool) -> Self {
        match after_transfer {
            true => LightEntry::FirstLayer {
                code_row: crate::network::design::TRANSPORT_CODE,
                own_row: 0,
            },
            false => LightEntry::FirstLayer {
                code_row: 0,
                own_row: CODE_SIZE,
            },
        }
    }

    /// The weight rows of Φ's first layer that multiply the light code; None when Φ does
    /// not read it.
    pub fn code_rows(self) -> Option<Range<usize>> {
        match self {
            LightEntry::FirstLayer { code_row, .. } => Some(code_row..code_row + CODE_SIZE),
            LightEntry::Combine { .. } => None,
        }
    }

    /// The first weight row of Φ's first layer that multiplies its per-row input.
    pub fn own_row(self) -> usize {
        match self {
            LightEntry::FirstLayer { own_row, .. } => own_row,
            LightEntry::Combine { .. } => 0,
        }
    }

    /// Values of the light code Φ's first layer reads (0 when it reads none).
    pub fn code_inputs(self) -> usize {
        self.code_rows().map_or(0, |r| r.len())
    }

    /// K, Φ's outputs per term and channel dotted with the code at the combine; 0 for the
    /// paper's, whose outputs are log-radiance (the kernels' convention).
    pub fn coefficients(self) -> usize {
        match self {
            LightEntry::FirstLayer { .. } => 0,
            LightEntry::Combine { k } => k,
        }
    }

    /// Whether a still camera keeps Φ's outputs: the lighting enters after the networks.
    pub fn after_networks(self) -> bool {
        matches!(self, LightEntry::Combine { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::network::design::TRANSPORT_CODE;

    #[test]
    fn the_code_and_the_own_input_share_no_row() {
        // [ê, inputs] and [ŝ, ê]: the code's rows end where the inputs start, or start where ŝ ends.
        let first = LightEntry::first_layer(false);
        assert_eq!(
            (first.code_rows(), first.own_row()),
            (Some(0..CODE_SIZE), CODE_SIZE)
        );
        let after = LightEntry::first_layer(true);
        let rows = TRANSPORT_CODE..TRANSPORT_CODE + CODE_SIZE;
        assert_eq!((after.code_rows(), after.own_row()), (Some(rows), 0));
        let linear = LightEntry::Combine { k: 25 };
        assert_eq!((linear.code_rows(), linear.own_row()), (None, 0));
        assert_eq!((linear.coefficients(), after.coefficients()), (25, 0));
        assert!(linear.after_networks() && !after.after_networks());
    }
}
