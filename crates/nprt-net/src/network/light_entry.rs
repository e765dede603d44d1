//! Where the lighting enters a track: the one fact about a track's sequence that every engine
//! needs besides its networks. It decides what a lighting change runs (everything from the
//! entry on) and what a still camera keeps (everything before it), and how the shading
//! network's first layer is laid out; the CPU engine, the GPU frame path and trainer and the
//! shader export read it from here instead of restating it from the design.

use std::ops::Range;

/// Where a track's shading network Φ meets the light code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightEntry {
    /// Φ's first layer reads the light code (the encoder's ê, or a basis projection) beside
    /// its per-row input: the code's `code_size` values multiply its weight rows from
    /// `code_row`, the per-row input those from `own_row`. A lighting folds the code's share
    /// into that layer's bias; a still camera keeps Φ's per-row input (ŝ, or the baseline's
    /// inputs).
    FirstLayer {
        code_row: usize,
        own_row: usize,
        code_size: usize,
    },
    /// Φ reads its per-row input alone and outputs K transfer coefficients per term and
    /// channel, each term their dot product with the light code (a basis projection) at the
    /// combine: a still camera keeps Φ's outputs, and a lighting runs only the combine.
    Combine { k: usize },
}

impl LightEntry {
    /// The paper's, for a code of `code_size` values: after the `own` rows of a per-row input
    /// (ŝ behind a transfer network: [ŝ, code]), else first ([code, inputs]).
    pub fn first_layer(own: Option<usize>, code_size: usize) -> Self {
        match own {
            Some(own) => LightEntry::FirstLayer {
                code_row: own,
                own_row: 0,
                code_size,
            },
            None => LightEntry::FirstLayer {
                code_row: 0,
                own_row: code_size,
                code_size,
            },
        }
    }

    /// The weight rows of Φ's first layer that multiply the light code; None when Φ does
    /// not read it.
    pub fn code_rows(self) -> Option<Range<usize>> {
        match self {
            LightEntry::FirstLayer {
                code_row,
                code_size,
                ..
            } => Some(code_row..code_row + code_size),
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
    use crate::network::encoder::CODE_SIZE;

    #[test]
    fn the_code_and_the_own_input_share_no_row() {
        // [ê, inputs] and [ŝ, ê]: the code's rows end where the inputs start, or start where ŝ ends.
        let first = LightEntry::first_layer(None, CODE_SIZE);
        assert_eq!(
            (first.code_rows(), first.own_row()),
            (Some(0..CODE_SIZE), CODE_SIZE)
        );
        let after = LightEntry::first_layer(Some(TRANSPORT_CODE), CODE_SIZE);
        let rows = TRANSPORT_CODE..TRANSPORT_CODE + CODE_SIZE;
        assert_eq!((after.code_rows(), after.own_row()), (Some(rows), 0));
        let linear = LightEntry::Combine { k: 25 };
        assert_eq!((linear.code_rows(), linear.own_row()), (None, 0));
        assert_eq!((linear.coefficients(), after.coefficients()), (25, 0));
        assert!(linear.after_networks() && !after.after_networks());
    }
}
