//! Making a dataset's pack from its views: under the dataset's packing lock, stamped with the
//! view files it was made from, written atomically, a chunk of views at a time on all cores.

use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::Path;

use anyhow::{bail, Context, Result};
use glam::Vec3;
use rayon::prelude::*;

use super::manifest::{Manifest, ViewRecord};
use super::pack_format::{
    PackHeader, PackedTarget, Prelude, MAGIC, PACK_FORMAT, PACK_VERSION, PRELUDE_BYTES,
};
use super::packed_pixel::{PackedPixel, PACKED_PIXEL_BYTES};
use super::packed_transfer;

/// Views read and encoded at once while packing: enough to keep every core busy, few enough
/// that their images stay well under a gigabyte at the paper's resolutions.
const PACK_CHUNK: usize = 32;

/// Takes the dataset's packing lock, waiting while another process holds it.
pub(super) fn lock_packing(dir: &Path) -> Result<File> {
    let path = dir.join(".packing.lock");
    let file = nprt_io::open_lock_file(&path).with_context(|| {
        format!(
            "cannot pack the dataset in '{}' (training packs it beside manifest.json; make the folder writable, or copy the dataset where it is)",
            dir.display()
        )
    })?;
    file.lock()
        .with_context(|| format!("cannot lock '{}'", path.display()))?;
    Ok(file)
}

/// BLAKE3 over each view file's name, size and modification time: a view redone or replaced
/// since packing changes it.
pub fn views_stamp(dir: &Path, manifest: &Manifest) -> Result<String> {
    let mut h = blake3::Hasher::new();
    for v in &manifest.views {
        let path = dir.join(&v.file);
        let meta = std::fs::metadata(&path)
            .with_context(|| format!("dataset view '{}' is missing", path.display()))?;
        let modified = meta
            .modified()
            .ok()
            .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
            .map_or(0, |d| d.as_nanos());
        h.update(v.file.as_bytes());
        h.update(&[0]);
        h.update(&meta.len().to_le_bytes());
        h.update(&modified.to_le_bytes());
    }
    Ok(h.finalize().to_hex().to_string())
}

/// Writes the pack of `target` for the dataset in `dir` (holding the packing lock).
pub(super) fn pack(
    path: &Path,
    dir: &Path,
    manifest: &Manifest,
    dataset_hash: &str,
    views_stamp: &str,
    target: PackedTarget,
    progress: bool,
) -> Result<()> {
    // Temporaries of a killed packing: ours, since the lock is held.
    nprt_io::remove_temporaries(dir, |of| of == path)?;
    nprt_io::write_atomically(path, |tmp| {
        let mut w = BufWriter::with_capacity(8 << 20, File::create(tmp)?);
        w.write_all(&[0; PRELUDE_BYTES])?;
        let bar = nprt_io::progress_bar(progress, manifest.views.len() as u64, "packing", "views");
        let mut hasher = blake3::Hasher::new();
        let mut views = Vec::with_capacity(manifest.views.len());
        let mut next = 0u64;
        let mut transfer = packed_transfer::Writer::new(dir, manifest)?;
        for chunk in manifest
            .views
            .chunks(packed_transfer::views_at_once(manifest, PACK_CHUNK))
        {
            let records: Vec<(Vec<PackedPixel>, Vec<u16>)> = chunk
                .par_iter()
                .map(|v| view_records(dir, manifest, v, target, transfer.is_some()))
                .collect::<Result<_>>()?;
            for (r, t) in records {
                let bytes: &[u8] = bytemuck::cast_slice(&r);
                hasher.update(bytes);
                w.write_all(bytes)?;
                if let Some(transfer) = &mut transfer {
                    transfer.add(&t, r.len())?;
                }
                views.push([next, r.len() as u64]);
                next += r.len() as u64;
                bar.inc(1);
            }
        }
        bar.finish_and_clear();
        let (transfer, transfer_len) = match transfer {
            Some(t) => t.append_to(&mut w)?,
            None => (None, 0),
        };
        let header = PackHeader {
            format: PACK_FORMAT.into(),
            version: PACK_VERSION,
            dataset_hash: dataset_hash.into(),
            views_stamp: views_stamp.into(),
            target,
            bounds: manifest.bounds,
            views,
            records_hash: hasher.finalize().to_hex().to_string(),
            transfer,
        };
        let json = serde_json::to_vec(&header)?;
        w.write_all(&json)?;
        let mut file = w.into_inner().map_err(|e| e.into_error())?;
        let records_len = next * PACKED_PIXEL_BYTES as u64;
        let prelude = Prelude {
            magic: MAGIC,
            version: PACK_VERSION,
            record_bytes: PACKED_PIXEL_BYTES as u32,
            records_offset: PRELUDE_BYTES as u64,
            records_len,
            header_offset: PRELUDE_BYTES as u64 + records_len + transfer_len,
            header_len: json.len() as u64,
            transfer_len,
            reserved: 0,
        };
        file.seek(SeekFrom::Start(0))?;
        file.write_all(bytemuck::bytes_of(&prelude))?;
        file.sync_all()?;
        Ok(())
    })
}

/// The records of one view's foreground pixels, refusing a position outside the scene bounds
/// (it could not be stored), and (`transfer`) their transfer vectors as `target` has them
/// (zero for a view without).
fn view_records(
    dir: &Path,
    manifest: &Manifest,
    view: &ViewRecord,
    target: PackedTarget,
    transfer: bool,
) -> Result<(Vec<PackedPixel>, Vec<u16>)> {
    let image = crate::views::load_view(dir, manifest, view)?;
    let g = &image.gbuffer;
    let [lo, hi] = manifest.bounds.map(Vec3::from);
    let slack = (hi - lo).max_element() * 1e-4;
    let mut records = Vec::with_capacity(image.foreground());
    for i in (0..g.mask.len()).filter(|&i| g.mask[i] > 0.5) {
        let s = g.sample(i);
        if s.position.cmplt(lo - slack).any() || s.position.cmpgt(hi + slack).any() {
            bail!(
                "pixel ({}, {}) of '{}' lies at {} outside the scene bounds {lo}..{hi} in manifest.json",
                i % image.width,
                i / image.width,
                dir.join(&view.file).display(),
                s.position
            );
        }
        let r = target.of(image.radiance[i], image.direct[i]);
        records.push(PackedPixel::encode(&s, r, &manifest.bounds));
    }
    let vectors = match (transfer, manifest.settings.transfer) {
        (true, Some(basis)) => {
            packed_transfer::vectors(&image, basis, target == PackedTarget::Indirect)
        }
        _ => vec![],
    };
    Ok((records, vectors))
}
