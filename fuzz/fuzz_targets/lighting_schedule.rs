//! Any text given as a lighting schedule must be refused or light every frame with one of its
//! segments at a finite rotation.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nprt_render::schedule::{parse_segments, segment_at};

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(segments) = parse_segments(text) {
            for frames in [1usize, 2, 7, 100] {
                for i in 0..frames {
                    let (k, rot) = segment_at(&segments, i, frames);
                    assert!(
                        k < segments.len() && rot.is_finite(),
                        "frame {i}/{frames}: ({k}, {rot})"
                    );
                }
            }
        }
    }
});
