//! Any text given as a Mitsuba scene must load or fail with an error, never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nprt_scene::mitsuba::parse;
use nprt_scene::SceneOptions;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        // Relative file references resolve inside the (empty) seed-corpus folder.
        let _ = parse(
            text,
            std::path::Path::new("fuzz/corpus/mitsuba_xml/scene.xml"),
            &SceneOptions::default(),
        );
    }
});
