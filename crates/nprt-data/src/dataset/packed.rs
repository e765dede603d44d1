//! The packed form of a dataset (docs/dataset.md, "Packed datasets"): every foreground pixel of
//! every view as one [`PackedPixel`] in a single file beside manifest.json, memory-mapped by
//! training, so that a set larger than memory trains with only the views in use resident. The
//! views stay the dataset: a pack is derived from them, made at first use, and made again when
//! the manifest or any view file changes. It is written atomically under a lock, so concurrent
//! trainings of one dataset pack it once. A dataset with transfer vectors (`--transfer`) packs
//! them after the records, one vector per record ([`super::packed_transfer`]).

use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, ensure, Context, Result};
use glam::Vec3;
use memmap2::{Mmap, UncheckedAdvice};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::manifest::{Manifest, ViewRecord};
use super::packed_pixel::{PackedPixel, PACKED_PIXEL_BYTES};
use super::packed_transfer::{self, PackedTransfer, TransferSection};

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
const MAGIC: [u8; 8] = *b"NPRTPACK";
/// The fixed part at the file's start; the records follow it, 64-byte aligned.
const PRELUDE_BYTES: usize = 64;
/// Views read and encoded at once while packing: enough to keep every core busy, few enough
/// that their images stay well under a gigabyte at the paper's resolutions.
const PACK_CHUNK: usize = 32;

/// Bytes hashed at once when a pack is opened.
const HASH_PIECE: usize = 256 << 20;

/// Where a pack sits in its file, written last at its start.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct Prelude {
    magic: [u8; 8],
    version: u32,
    record_bytes: u32,
    records_offset: u64,
    records_len: u64,
    header_offset: u64,
    header_len: u64,
    /// Bytes of transfer vectors between the records and the header (0: none).
    transfer_len: u64,
    reserved: u64,
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

/// A pack opened for reading.
pub struct PackedDataset {
    header: PackHeader,
    records: Records,
}

enum Records {
    /// The file at `path`, `len` bytes of records after the prelude, then `transfer_len`
    /// bytes of transfer vectors.
    Mapped {
        map: Mmap,
        len: usize,
        transfer_len: usize,
        path: PathBuf,
    },
    /// Built in memory (tests, small sets).
    Memory(Vec<PackedPixel>),
}

impl PackedDataset {
    /// The pack of `target` in dataset folder `dir`.
    pub fn path(dir: &Path, target: PackedTarget) -> PathBuf {
        dir.join(format!("packed-{}.bin", target.name()))
    }

    /// The dataset's pack of `target`, made first if it is missing or no longer matches the
    /// dataset (`on_pack` is told why before packing starts).
    pub fn open_or_pack(
        dir: &Path,
        manifest: &Manifest,
        dataset_hash: &str,
        target: PackedTarget,
        progress: bool,
        on_pack: impl Fn(&str),
    ) -> Result<Self> {
        let path = Self::path(dir, target);
        let stamp = views_stamp(dir, manifest)?;
        let current = || Self::open_current(dir, manifest, dataset_hash, &stamp, target);
        let why = match current() {
            Ok(pack) => return Ok(pack),
            Err(_) if !path.exists() => format!("packing '{}'", dir.display()),
            Err(e) => format!("packing '{}' again: {e:#}", dir.display()),
        };
        let lock = lock_packing(dir)?;
        // Another process may have packed it while this one waited for the lock.
        if let Ok(pack) = current() {
            return Ok(pack);
        }
        on_pack(&why);
        pack(dir, manifest, dataset_hash, &stamp, target, progress)?;
        drop(lock);
        current()
    }

    /// The pack of `target` in `dir` if it [opens](Self::open) and was made from the view files
    /// as they are now (`views_stamp`).
    pub fn open_current(
        dir: &Path,
        manifest: &Manifest,
        dataset_hash: &str,
        views_stamp: &str,
        target: PackedTarget,
    ) -> Result<Self> {
        let path = Self::path(dir, target);
        let pack = Self::open(&path, manifest, dataset_hash, target)?;
        ensure!(
            pack.header.views_stamp == views_stamp,
            "a view file changed since '{}' was packed",
            path.display()
        );
        Ok(pack)
    }

    /// Opens the pack at `path`, refusing one not made from this manifest, of another target,
    /// or whose records differ from those it was written with.
    pub fn open(
        path: &Path,
        manifest: &Manifest,
        dataset_hash: &str,
        target: PackedTarget,
    ) -> Result<Self> {
        nprt_io::check_input(path)?;
        let file = File::open(path).with_context(|| format!("cannot open '{}'", path.display()))?;
        // SAFETY: packs are only ever replaced by rename, never changed in place, so the mapped
        // file stays as it was while mapped.
        let map = unsafe { Mmap::map(&file) }
            .with_context(|| format!("cannot map '{}'", path.display()))?;
        let (header, len, transfer_len) = read_header(&map)
            .with_context(|| format!("'{}' is not a usable pack", path.display()))?;
        ensure!(
            header.dataset_hash == dataset_hash,
            "manifest.json changed since '{}' was packed",
            path.display()
        );
        ensure!(
            header.target == target && header.bounds == manifest.bounds,
            "'{}' holds other targets or bounds than its name says",
            path.display()
        );
        check_view_ranges(&header, manifest, len / PACKED_PIXEL_BYTES)
            .and_then(|()| {
                let records = len / PACKED_PIXEL_BYTES;
                packed_transfer::check(header.transfer.as_ref(), manifest, records, transfer_len)
            })
            .with_context(|| format!("'{}' does not match its manifest", path.display()))?;
        let pack = PackedDataset {
            header,
            records: Records::Mapped {
                map,
                len,
                transfer_len,
                path: path.to_path_buf(),
            },
        };
        pack.check_records()?;
        nprt_io::name_on_bus_error(path);
        Ok(pack)
    }

    /// Hashes the records again against the hash written with them: a pack changed since it
    /// was opened (random bytes written over it during a training) is told apart from a
    /// training that diverged by itself. A pack built in memory has nothing to check.
    pub fn check_records(&self) -> Result<()> {
        let Records::Mapped { path, .. } = &self.records else {
            return Ok(());
        };
        ensure!(
            self.hash_released(0, bytemuck::cast_slice(self.records())) == self.header.records_hash,
            "the records of '{}' are damaged (their hash differs from the one written)",
            path.display()
        );
        if let Some(t) = &self.header.transfer {
            let start = self.bytes();
            let hash = self.hash_released(start, bytemuck::cast_slice(self.transfer_values()));
            ensure!(
                hash == t.hash,
                "the transfer vectors of '{}' are damaged (their hash differs from the one written)",
                path.display()
            );
        }
        Ok(())
    }

    /// A pack held in memory: `views[i]` are the records of view i. It names no dataset and
    /// holds no hashes: nothing on disk to check it against.
    pub fn from_records(
        bounds: [[f32; 3]; 2],
        target: PackedTarget,
        views: Vec<Vec<PackedPixel>>,
    ) -> Self {
        let mut ranges = Vec::with_capacity(views.len());
        let mut first = 0u64;
        for v in &views {
            ranges.push([first, v.len() as u64]);
            first += v.len() as u64;
        }
        let records: Vec<PackedPixel> = views.into_iter().flatten().collect();
        let header = PackHeader {
            format: PACK_FORMAT.into(),
            version: PACK_VERSION,
            dataset_hash: String::new(),
            views_stamp: String::new(),
            target,
            bounds,
            views: ranges,
            records_hash: String::new(),
            transfer: None,
        };
        PackedDataset {
            header,
            records: Records::Memory(records),
        }
    }

    pub fn header(&self) -> &PackHeader {
        &self.header
    }

    /// Every record, views one after another in manifest order (as a GPU engine uploads them).
    pub fn records(&self) -> &[PackedPixel] {
        match &self.records {
            Records::Mapped { map, len, .. } => {
                bytemuck::cast_slice(&map[PRELUDE_BYTES..PRELUDE_BYTES + len])
            }
            Records::Memory(r) => r,
        }
    }

    /// BLAKE3 of `bytes`, the file's from `start` after the prelude, in pieces, each let go once
    /// hashed, so that checking a pack larger than memory never holds more than one piece.
    fn hash_released(&self, start: usize, bytes: &[u8]) -> String {
        let mut hasher = blake3::Hasher::new();
        for (i, piece) in bytes.chunks(HASH_PIECE).enumerate() {
            hasher.update_rayon(piece);
            self.release_bytes(start + i * HASH_PIECE, piece.len());
        }
        hasher.finalize().to_hex().to_string()
    }

    /// Every record's transfer vector, one after another (empty without them).
    fn transfer_values(&self) -> &[u16] {
        match &self.records {
            Records::Mapped {
                map,
                len,
                transfer_len,
                ..
            } => bytemuck::cast_slice(&map[PRELUDE_BYTES + len..][..*transfer_len]),
            Records::Memory(_) => &[],
        }
    }

    /// The transfer vectors of the manifest's view `i` (None: the pack holds none).
    pub fn transfer(&self, i: usize) -> Option<TransferSection<'_>> {
        let t = self.header.transfer.as_ref()?;
        let [first, count] = self.header.views[i];
        let n = t.basis.floats();
        let values = &self.transfer_values()[first as usize * n..(first + count) as usize * n];
        Some(TransferSection {
            basis: t.basis,
            values,
        })
    }

    /// The records of the manifest's view `i`.
    pub fn view(&self, i: usize) -> &[PackedPixel] {
        let [first, count] = self.header.views[i];
        &self.records()[first as usize..(first + count) as usize]
    }

    /// Bytes the records take.
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.records())
    }

    /// Lets go of view `i`'s pages: they stay in the page cache, but no longer count as this
    /// process's memory until read again.
    pub fn release(&self, i: usize) {
        let [first, count] = self.header.views[i];
        self.release_bytes(
            first as usize * PACKED_PIXEL_BYTES,
            count as usize * PACKED_PIXEL_BYTES,
        );
        if let (Some(t), Records::Mapped { len, .. }) = (&self.header.transfer, &self.records) {
            let per = t.basis.floats() * 2;
            self.release_bytes(len + first as usize * per, count as usize * per);
        }
    }

    fn release_bytes(&self, start: usize, len: usize) {
        if let (Records::Mapped { map, .. }, true) = (&self.records, len > 0) {
            // SAFETY: a read-only shared file mapping: dropped pages are read from the file again
            // when next touched, so no content is lost. Failure only leaves pages resident.
            let _ = unsafe {
                map.unchecked_advise_range(UncheckedAdvice::DontNeed, PRELUDE_BYTES + start, len)
            };
        }
    }
}

/// Takes the dataset's packing lock, waiting while another process holds it.
fn lock_packing(dir: &Path) -> Result<File> {
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
fn pack(
    dir: &Path,
    manifest: &Manifest,
    dataset_hash: &str,
    views_stamp: &str,
    target: PackedTarget,
    progress: bool,
) -> Result<()> {
    let path = PackedDataset::path(dir, target);
    // Temporaries of a killed packing: ours, since the lock is held.
    nprt_io::remove_temporaries(dir, |of| of == path)?;
    nprt_io::write_atomically(&path, |tmp| {
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

/// The header of a mapped pack, its records' and its transfer vectors' lengths in bytes, after
/// checking that every part lies where the prelude says.
fn read_header(bytes: &[u8]) -> Result<(PackHeader, usize, usize)> {
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

/// Each view's records lie within the file, one after another, at most one per pixel.
fn check_view_ranges(header: &PackHeader, manifest: &Manifest, records: usize) -> Result<()> {
    ensure!(
        header.views.len() == manifest.views.len(),
        "{} views packed, {} in the manifest",
        header.views.len(),
        manifest.views.len()
    );
    let mut next = 0u64;
    for (v, &[first, count]) in manifest.views.iter().zip(&header.views) {
        ensure!(
            first == next && count <= v.width as u64 * v.height as u64,
            "view {} claims records {first}..+{count}",
            v.index
        );
        next = first + count;
    }
    ensure!(
        next == records as u64,
        "{next} records listed, {records} stored"
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::cell::RefCell;

    use super::*;
    use crate::dataset::packed_pixel::tests::angle;
    use crate::dataset::plan::room_request;
    use crate::dataset::{plan, prepare, run, Request, ViewSpec};
    use nprt_scene::{load_scene, SceneOptions};
    use nprt_trace::{TraceScene, Tracer};

    /// A three-view dataset of the built-in room in a fresh folder, its manifest and hash.
    fn room(name: &str) -> (PathBuf, Manifest, String) {
        let scene = load_scene("builtin:room", &SceneOptions::default()).unwrap();
        let ts = TraceScene::new(&scene);
        let base = room_request(&scene, ["builtin:sky", "builtin:indoor:1"]);
        let request = Request {
            views: ViewSpec {
                train_views: 2,
                train_resolution: [12, 10],
                test_resolution: [16, 16],
                spp: 4,
                test_spp: 4,
                seed: 3,
                ..base.views
            },
            ..base
        };
        let manifest = plan(&request, &ts).unwrap();
        let dir = std::env::temp_dir().join(format!("nprt-pack-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        prepare(&dir, &manifest).unwrap();
        run(
            &Tracer::Cpu(&ts),
            &request.maps,
            &manifest,
            &dir,
            (0, 1),
            false,
        )
        .unwrap();
        let (manifest, hash) = crate::dataset::load_manifest_hashed(&dir).unwrap();
        (dir, manifest, hash)
    }

    #[test]
    fn a_pack_holds_every_foreground_pixel_as_its_view_has_it() {
        let (dir, manifest, hash) = room("content");
        for target in [PackedTarget::Radiance, PackedTarget::Indirect] {
            let pack =
                PackedDataset::open_or_pack(&dir, &manifest, &hash, target, false, |_| {}).unwrap();
            for (i, v) in manifest.views.iter().enumerate() {
                let image = crate::views::load_view(&dir, &manifest, v).unwrap();
                let g = &image.gbuffer;
                let foreground: Vec<usize> =
                    (0..g.mask.len()).filter(|&p| g.mask[p] > 0.5).collect();
                let records = pack.view(i);
                assert!(!records.is_empty());
                assert_eq!(records.len(), foreground.len());
                for (r, &p) in records.iter().zip(&foreground) {
                    let (s, radiance) = r.decode(&manifest.bounds);
                    let want = g.sample(p);
                    assert!((s.position - want.position).abs().max_element() < 1e-3);
                    assert!(angle(s.normal, want.normal) < 1e-4);
                    assert!(angle(s.view, want.view) < 1e-4);
                    assert!((s.kd - want.kd).abs().max_element() < 1e-3);
                    assert!((s.ks - want.ks).abs().max_element() < 1e-3);
                    assert!((s.alpha - want.alpha).abs() < 1e-3);
                    let (total, direct) = (image.radiance[p], image.direct[p]);
                    let expected = match target {
                        PackedTarget::Radiance => total,
                        PackedTarget::Indirect => (total - direct).max(Vec3::ZERO),
                    };
                    assert_eq!(radiance, expected);
                }
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_pack_that_no_longer_matches_its_dataset_is_made_again() {
        let (dir, manifest, hash) = room("stale");
        let target = PackedTarget::Radiance;
        let path = PackedDataset::path(&dir, target);
        let said = RefCell::new(Vec::<String>::new());
        let open = || {
            said.borrow_mut().clear();
            let pack = PackedDataset::open_or_pack(&dir, &manifest, &hash, target, false, |why| {
                said.borrow_mut().push(why.to_string())
            })
            .unwrap();
            (pack.records().len(), said.borrow().join(" "))
        };
        // A leftover of a killed packing is removed by the next.
        let leftover = dir.join(".packed-radiance.bin.1.tmp");
        std::fs::write(&leftover, b"partial").unwrap();
        let (records, why) = open();
        assert!(why.starts_with("packing"), "{why}");
        assert!(!leftover.exists());
        assert_eq!(
            open(),
            (records, String::new()),
            "a current pack is used as it is"
        );

        let damage = |edit: &dyn Fn(&mut Vec<u8>), expected: &str| {
            let mut bytes = std::fs::read(&path).unwrap();
            edit(&mut bytes);
            std::fs::write(&path, &bytes).unwrap();
            let (again, why) = open();
            assert_eq!(again, records);
            assert!(why.contains(expected), "{expected}: {why}");
        };
        damage(&|b| b[PRELUDE_BYTES + 13] ^= 4, "damaged");
        damage(&|b| b.truncate(b.len() - 1), "truncated");
        damage(
            &|b| b[..8].copy_from_slice(b"NOTAPACK"),
            "not a packed dataset",
        );
        // A view file redone after packing.
        let view = dir.join(&manifest.views[1].file);
        let bytes = std::fs::read(&view).unwrap();
        std::thread::sleep(std::time::Duration::from_millis(20));
        std::fs::write(&view, bytes).unwrap();
        let (again, why) = open();
        assert_eq!(again, records);
        assert!(why.contains("a view file changed"), "{why}");
        // Another manifest (a dataset generated again with other settings in the same folder).
        let err = PackedDataset::open(&path, &manifest, "another", target)
            .err()
            .unwrap();
        assert!(
            format!("{err:#}").contains("manifest.json changed"),
            "{err:#}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

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
