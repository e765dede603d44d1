//! Any bytes given as a dataset folder (a manifest and one view file) must be refused or load
//! as the pipeline trusts them: a view read back matches its record's size and holds finite,
//! non-negative radiance. Input: a little-endian u32 length, that many bytes of manifest.json,
//! then the bytes of the first view's OpenEXR file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nprt_data::dataset::{read_view, Manifest};

fuzz_target!(|data: &[u8]| {
    let Some((len, rest)) = data.split_first_chunk::<4>() else {
        return;
    };
    let len = (u32::from_le_bytes(*len) as usize).min(rest.len());
    let (json, exr) = rest.split_at(len);
    let Ok(manifest) = Manifest::from_json(json) else {
        return;
    };
    let view = &manifest.views[0];
    // Views larger than libFuzzer's 2 GB allocation limit may be real; refusing what this
    // machine cannot hold is nprt_io::ensure_memory's job, tested apart.
    if view.width as u64 * view.height as u64 > 1 << 20 {
        return;
    }
    let dir = std::env::temp_dir().join(format!("nprt-fuzz-dataset-{}", std::process::id()));
    let path = dir.join(&view.file);
    // A name the file system cannot hold here ("", ".", too long) is not the loader's concern.
    let written = path
        .parent()
        .is_some_and(|p| std::fs::create_dir_all(p).is_ok())
        && std::fs::write(&path, exr).is_ok();
    if !written {
        return;
    }
    if let Ok(image) = read_view(&path, view, manifest.settings.in_halves(view)) {
        let f = &image.frame;
        assert_eq!(
            (f.width, f.height),
            (view.width as usize, view.height as usize)
        );
        assert!(f
            .radiance
            .iter()
            .all(|c| c.is_finite() && c.min_element() >= 0.0));
        assert!(image
            .half
            .iter()
            .flatten()
            .all(|c| c.is_finite() && c.min_element() >= 0.0));
    }
});
