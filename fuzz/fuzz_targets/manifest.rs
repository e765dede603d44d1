//! Any bytes given as a dataset manifest must be refused or be safe to use as the pipeline
//! uses it: every view's map, camera and size.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nprt_data::dataset::Manifest;

fuzz_target!(|data: &[u8]| {
    if let Ok(m) = Manifest::from_json(data) {
        let maps = m.settings.envmaps.len();
        for v in &m.views {
            assert!(v.map < maps, "a checked manifest indexes its maps safely");
            let c = v.camera();
            let _ = c.ray(glam::Vec2::new(0.5, 0.5));
        }
    }
});
