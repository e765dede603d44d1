//! What a view file holds beside its frame, as its manifest says: what reading it checks.

use super::transfer::TransferBasis;

/// What a view file holds beside its frame ([`super::Settings::parts`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewParts {
    /// The first half's radiance (a test view rendered in halves).
    pub halves: bool,
    /// Transfer vectors on this basis.
    pub transfer: Option<TransferBasis>,
}
