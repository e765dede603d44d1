//! A pack's transfer vectors (`nprt generate --transfer`): after the records, one vector per
//! record in record order, (L+1)² coefficients × RGB as f16 bits, as the pack's target has them
//! (whole, or without the direct part); zero for a test view, which records none.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{ensure, Context, Result};
use half::f16;
use serde::{Deserialize, Serialize};

use super::manifest::Manifest;
use super::transfer::TransferBasis;
use crate::views::ImageView;

/// What the pack header says of its transfer vectors.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PackedTransfer {
    pub basis: TransferBasis,
    /// BLAKE3 of the vectors' bytes.
    pub hash: String,
}

/// One view's transfer vectors in a pack.
pub struct TransferSection<'a> {
    pub basis: TransferBasis,
    /// f16 bits, `basis.floats()` per record.
    pub values: &'a [u16],
}

impl TransferSection<'_> {
    /// Record `p`'s first `coefficients` coefficients (a basis of fewer bands is a prefix of a
    /// larger one), R G B each.
    pub fn vector(&self, p: usize, coefficients: usize) -> impl Iterator<Item = f32> + '_ {
        let n = self.basis.floats();
        let take = (3 * coefficients).min(n);
        self.values[p * n..p * n + take]
            .iter()
            .map(|&b| f16::from_bits(b).to_f32())
    }
}

/// The foreground pixels' vectors of `image` as a pack learns them (`indirect`: without their
/// direct part), in record order.
pub(crate) fn vectors(image: &ImageView, basis: TransferBasis, indirect: bool) -> Vec<u16> {
    let mask = &image.gbuffer.mask;
    let foreground = (0..mask.len()).filter(|&i| mask[i] > 0.5);
    let Some(t) = &image.transfer else {
        return vec![0; foreground.count() * basis.floats()];
    };
    foreground
        .flat_map(|i| t.pixel(i, indirect).map(|x| f16::from_f32(x).to_bits()))
        .collect()
}

/// Views to pack at once, at most `most`: fewer where their transfer vectors, as read (f32,
/// whole and direct), would pass 1 GiB.
pub(crate) fn views_at_once(manifest: &Manifest, most: usize) -> usize {
    let Some(basis) = manifest.settings.transfer else {
        return most;
    };
    let [w, h] = manifest.settings.train_resolution;
    let per_view = w as usize * h as usize * 2 * basis.floats() * 4;
    ((1 << 30) / per_view.max(1)).clamp(1, most)
}

/// Collects the vectors while the records are written, in a file beside the pack (the records
/// come first in it), then appends them after the records; the file goes with the writer.
pub(crate) struct Writer {
    path: PathBuf,
    file: BufWriter<File>,
    hasher: blake3::Hasher,
    basis: TransferBasis,
    bytes: u64,
}

impl Writer {
    /// A writer where `manifest` records transfer vectors (holding the packing lock).
    pub fn new(dir: &Path, manifest: &Manifest) -> Result<Option<Self>> {
        let Some(basis) = manifest.settings.transfer else {
            return Ok(None);
        };
        let path = dir.join(".packing-transfer.part");
        let file =
            File::create(&path).with_context(|| format!("cannot create '{}'", path.display()))?;
        Ok(Some(Writer {
            path,
            file: BufWriter::with_capacity(8 << 20, file),
            hasher: blake3::Hasher::new(),
            basis,
            bytes: 0,
        }))
    }

    /// Adds the vectors of a view's `records` records.
    pub fn add(&mut self, vectors: &[u16], records: usize) -> Result<()> {
        ensure!(
            vectors.len() == records * self.basis.floats(),
            "{} transfer values for {records} records of {} each",
            vectors.len(),
            self.basis.floats()
        );
        let bytes: Vec<u8> = vectors.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.hasher.update(&bytes);
        self.file.write_all(&bytes)?;
        self.bytes += bytes.len() as u64;
        Ok(())
    }

    /// Appends the vectors to `out`; returns the header's part and their length in bytes.
    pub fn append_to(mut self, out: &mut impl Write) -> Result<(Option<PackedTransfer>, u64)> {
        self.file.flush()?;
        let mut part = File::open(&self.path)?;
        let copied = std::io::copy(&mut part, out)?;
        ensure!(
            copied == self.bytes,
            "the transfer vectors' part file was cut short"
        );
        let header = PackedTransfer {
            basis: self.basis,
            hash: self.hasher.finalize().to_hex().to_string(),
        };
        Ok((Some(header), self.bytes))
    }
}

impl Drop for Writer {
    fn drop(&mut self) {
        // Done or failed, the part file is not kept (a killed packing's is truncated by the next).
        let _ = std::fs::remove_file(&self.path);
    }
}

/// A pack's transfer vectors (`packed`, `transfer_len` bytes for `records` records) are the
/// manifest's: same basis, one vector per record.
pub(crate) fn check(
    packed: Option<&PackedTransfer>,
    manifest: &Manifest,
    records: usize,
    transfer_len: usize,
) -> Result<()> {
    let (packed, asked) = (packed.map(|t| t.basis), manifest.settings.transfer);
    ensure!(
        packed == asked,
        "it holds transfer vectors {}, the manifest records {}",
        packed.map_or("none".into(), |b| b.to_string()),
        asked.map_or("none".into(), |b| b.to_string())
    );
    let per = packed.map_or(0, |b| 2 * b.floats());
    ensure!(
        transfer_len == records * per,
        "{transfer_len} bytes of transfer vectors for {records} records of {per}"
    );
    Ok(())
}
