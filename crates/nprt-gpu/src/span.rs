//! Where one tensor lies in a flat device buffer, so that a kernel can bind it on its own.

/// A run of f32 elements of a buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Span {
    pub offset: usize,
    pub len: usize,
}

impl Span {
    /// The byte range, for binding this tensor alone.
    pub fn bytes(self) -> (u64, u64) {
        ((self.offset * 4) as u64, (self.len * 4) as u64)
    }
}
