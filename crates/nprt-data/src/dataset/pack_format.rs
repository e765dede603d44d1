//! A pack's file (docs/dataset.md, "Packed datasets"): the fixed prelude at its start that says
//! where each part lies, then the records, the transfer vectors and the JSON header that
//! describes them; and what a pack's radiance holds ([`PackedTarget`]). Written by
//! `packing.rs`, read by `packed.rs`.

use anyhow::{ensure, Context, Result};
use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::packed_pixel::PACKED_PIXEL_BYTES;
use super::packed_transfer::PackedTransfer;

/// What a pack's radiance holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PackedTarget {
    /// The reference radiance.
    Radiance,
    /// The reference minus its direct part (never below zero), for models that trace the
    /// direct light at run time.
    Indirect,
}

impl PackedTarget {
    pub fn name(self) -> &'static str {
        match self {
            PackedTarget::Radiance => "radiance",
            PackedTarget::Indirect => "indirect",
        }
    }

    /// The value learned for a pixel of `radiance` whose direct part is `direct`.
    pub fn of(self, radiance: Vec3, direct: Vec3) -> Vec3 {
        match self {
            PackedTarget::Radiance => radiance,
            PackedTarget::Indirect => (radiance - direct).max(Vec3::ZERO),
        }
    }
}
pub const PACK_FORMAT: &str = "nprt-packed-dataset";
pub const PACK_VERSION: u32 = 1;
pub(super) const MAGIC: [u8; 8] = *b"NPRTPACK";
/// The fixed part at the file's start; the records follow it, 64-byte aligned.
pub(super) const PRELUDE_BYTES: usize = 64;

/// Where a pack sits in its file, written last at its start.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct Prelude {
    pub(super) magic: [u8; 8],
    pub(super) version: u32,
    pub(super) record_bytes: u32,
    pub(super) records_offset: u64,
    pub(super) records_len: u64,
    pub(super) header_offset: u64,
    pub(super) header_len: u64,
    /// Bytes of transfer vectors between the records and the header (0: none).
    pub(super) transfer_len: u64,
    pub(super) reserved: u64,
}

/// The pack's description, JSON after the records.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PackHeader {
    pub format: String,
    pub version: u32,
    /// BLAKE3 of the manifest.json it was made from.
    pub dataset_hash: String,
    /// BLAKE3 over the view files' names, sizes and modification times.
    pub views_stamp: String,
    pub target: PackedTarget,
    /// The scene bounds positions are stored within.
    pub bounds: [[f32; 3]; 2],
    /// Per manifest view, in its order: first record and record count.
    pub views: Vec<[u64; 2]>,
    /// BLAKE3 of the records.
    pub records_hash: String,
    /// The transfer vectors after the records, for a dataset made with `--transfer`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transfer: Option<PackedTransfer>,
}
/// The header of a mapped pack, its records' and its transfer vectors' lengths in bytes, after
/// checking that every part lies where the prelude says.
pub(super) fn read_header(bytes: &[u8]) -> Result<(PackHeader, usize, usize)> {
    ensure!(bytes.len() >= PRELUDE_BYTES, "shorter than its prelude");
    let p: Prelude = bytemuck::pod_read_unaligned(&bytes[..PRELUDE_BYTES]);
    ensure!(
        p.magic == MAGIC,
        "not a packed dataset (no NPRTPACK signature)"
    );
    ensure!(
        p.version == PACK_VERSION && p.record_bytes as usize == PACKED_PIXEL_BYTES,
        "pack version {} with {}-byte records; this nprt reads version {PACK_VERSION}",
        p.version,
        p.record_bytes
    );
    let len = bytes.len() as u64;
    let fits = |offset: u64, n: u64| offset.checked_add(n).is_some_and(|end| end <= len);
    ensure!(
        p.records_offset == PRELUDE_BYTES as u64
            && p.records_len.is_multiple_of(PACKED_PIXEL_BYTES as u64)
            && Some(p.header_offset)
                == (p.records_offset + p.records_len).checked_add(p.transfer_len)
            && fits(p.header_offset, p.header_len)
            && p.header_offset + p.header_len == len,
        "its parts do not fit its {len} bytes (truncated or not written to the end)"
    );
    let json = &bytes[p.header_offset as usize..(p.header_offset + p.header_len) as usize];
    let header: PackHeader = serde_json::from_slice(json).context("its header is not valid")?;
    ensure!(
        header.format == PACK_FORMAT && header.version == PACK_VERSION,
        "its header says format '{}' version {}",
        header.format,
        header.version
    );
    Ok((header, p.records_len as usize, p.transfer_len as usize))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_indirect_target_is_the_rest_of_the_radiance_never_negative() {
        let radiance = Vec3::new(1.0, 2.0, 0.5);
        // The last channel's direct part exceeds its total by a rounding error.
        let direct = Vec3::new(0.25, 0.5, 0.5000001);
        assert_eq!(PackedTarget::Radiance.of(radiance, direct), radiance);
        assert_eq!(
            PackedTarget::Indirect.of(radiance, direct),
            Vec3::new(0.75, 1.5, 0.0)
        );
    }
}
