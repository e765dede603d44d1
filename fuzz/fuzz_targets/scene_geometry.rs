//! Any shapes and transforms a Mitsuba scene can state, at any magnitude, must be refused by
//! the scene's extent check or built into a BVH that rays then traverse: never a panic and
//! never a hang (the builder once indexed out of bounds at 10¹⁹ and looped at 10³⁰).
#![no_main]

use libfuzzer_sys::fuzz_target;
use nprt_scene::mitsuba::parse;
use nprt_scene::SceneOptions;
use nprt_trace::TraceScene;

/// The fuzzer's bytes as f32 values, four bytes each, NaN and infinities included.
fn floats(data: &[u8]) -> impl Iterator<Item = f32> + '_ {
    data.chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

fuzz_target!(|data: &[u8]| {
    let Some((&kinds, rest)) = data.split_first() else {
        return;
    };
    let mut v = floats(rest);
    let mut next = || v.next().unwrap_or(1.0);
    let mut xml = String::from(r#"<scene version="3.0.0">"#);
    // Up to four shapes, each one of the kinds below under a transform of the fuzzer's values.
    for s in 0..4 {
        let (a, b, c) = (next(), next(), next());
        let transform = match (kinds >> (2 * s)) & 3 {
            0 => format!(r#"<scale value="{a:e}, {b:e}, {c:e}"/>"#),
            1 => format!(r#"<translate value="{a:e}, {b:e}, {c:e}"/>"#),
            2 => format!(r#"<rotate x="1" angle="{a:e}"/><scale value="{b:e}"/>"#),
            _ => {
                let m: Vec<String> = (0..16).map(|_| format!("{:e}", next())).collect();
                format!(r#"<matrix value="{}"/>"#, m.join(" "))
            }
        };
        let shape = match s {
            0 => "rectangle".to_string(),
            1 => format!(
                r#"sphere"><float name="radius" value="{:e}"/><point name="center" value="{:e}, 0, 0""#,
                next(),
                next()
            ),
            2 => "cube".to_string(),
            _ => "rectangle".to_string(),
        };
        let (open, close) = match shape.split_once('"') {
            Some((kind, params)) => (format!(r#"<shape type="{kind}">{params}/>"#), "</shape>"),
            None => (format!(r#"<shape type="{shape}">"#), "</shape>"),
        };
        xml += &format!(r#"{open}<transform name="to_world">{transform}</transform>{close}"#);
    }
    xml += "</scene>";
    let path = std::path::Path::new("fuzz/corpus/scene_geometry/scene.xml");
    let Ok(scene) = parse(&xml, path, &SceneOptions::default()) else {
        return;
    };
    if scene.check_extent("fuzzed scene").is_err() {
        return;
    }
    let ts = TraceScene::new(&scene);
    let origin = glam::Vec3::new(next(), next(), next());
    if origin.is_finite() {
        let dir = glam::Vec3::new(0.3, -0.5, 0.8).normalize();
        let _ = ts.accel.intersect(origin, dir, f32::INFINITY);
        let _ = ts.accel.occluded(origin, -dir, 1e9);
    }
});
