//! The packed form of a dataset (docs/dataset.md, "Packed datasets"): every foreground pixel of
//! every view as one [`PackedPixel`] in a single file beside manifest.json, memory-mapped by
//! training, so that a set larger than memory trains with only the views in use resident. The
//! views stay the dataset: a pack is derived from them, made at first use, and made again when
//! the manifest or any view file changes. It is written atomically under a lock, so concurrent
//! trainings of one dataset pack it once. A dataset with transfer vectors (`--transfer`) packs
//! them after the records, one vector per record ([`super::packed_transfer`]).

use std::fs::File;
use std::path::{Path, PathBuf};

use anyhow::{ensure, Context, Result};
use memmap2::{Mmap, UncheckedAdvice};

use super::manifest::Manifest;
use super::pack_format::{
    read_header, PackHeader, PackedTarget, PACK_FORMAT, PACK_VERSION, PRELUDE_BYTES,
};
use super::packed_pixel::{PackedPixel, PACKED_PIXEL_BYTES};
use super::packed_transfer::{self, TransferSection};
use super::packing::{lock_packing, pack, views_stamp};

/// Bytes hashed at once when a pack is opened.
const HASH_PIECE: usize = 256 << 20;

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
        pack(&path, dir, manifest, dataset_hash, &stamp, target, progress)?;
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

    use glam::Vec3;

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
}
