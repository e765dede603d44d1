//! Any text given as a camera path must be refused or give a camera at every time.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nprt_render::CameraPath;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(path) = CameraPath::from_json(text) {
            for i in 0..=8 {
                let c = path.camera(i as f32 / 8.0, 16, 9);
                let _ = c.ray(glam::Vec2::new(8.0, 4.5));
            }
        }
    }
});
