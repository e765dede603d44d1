//! Any bytes given as a dataset's pack must be refused or open as training trusts them: every
//! view's records lie within the file, and they decode. Input: a little-endian u32 length, that
//! many bytes of manifest.json, then the bytes of packed-radiance.bin (the manifest's BLAKE3 is
//! the dataset hash the pack must name, as in a real folder).
#![no_main]

use libfuzzer_sys::fuzz_target;
use nprt_data::dataset::{Manifest, PackedDataset, PackedTarget};

fuzz_target!(|data: &[u8]| {
    let Some((len, rest)) = data.split_first_chunk::<4>() else {
        return;
    };
    let len = (u32::from_le_bytes(*len) as usize).min(rest.len());
    let (json, pack) = rest.split_at(len);
    let Ok(manifest) = Manifest::from_json(json) else {
        return;
    };
    let hash = blake3::hash(json).to_hex().to_string();
    let dir = std::env::temp_dir().join(format!("nprt-fuzz-pack-{}", std::process::id()));
    let path = PackedDataset::path(&dir, PackedTarget::Radiance);
    if std::fs::create_dir_all(&dir).is_err() || std::fs::write(&path, pack).is_err() {
        return;
    }
    if let Ok(p) = PackedDataset::open(&path, &manifest, &hash, PackedTarget::Radiance) {
        let bounds = p.header().bounds;
        for i in 0..manifest.views.len() {
            for r in p.view(i) {
                let (s, _) = r.decode(&bounds);
                assert!(s.normal.is_finite() && s.view.is_finite());
            }
        }
    }
});
