//! `nprt bake` end to end at the test-only size: a scene to a relit model in one command, its
//! summary and pictures, a kill mid-training resumed to the weights of a run never killed, and
//! what it refuses before any work.

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{assets, fails, fresh_dir, ok};

/// Passes over the tiny dataset: training lasts seconds, long enough to be killed within.
const EPOCHS: &str = "60";

fn bake_args<'a>(out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "bake",
        "builtin:room",
        "--envmaps",
        "builtin",
        "--out",
        out,
        "--quality",
        "tiny",
        "--epochs",
        EPOCHS,
        "--device",
        "cpu",
    ];
    args.extend_from_slice(extra);
    args
}

fn weights(model: &Path) -> Vec<u8> {
    std::fs::read(model.join("weights.safetensors")).unwrap()
}

#[test]
fn a_bake_makes_the_recipes_model_and_a_killed_one_resumes_to_the_same_weights() {
    let dir = fresh_dir("bake");
    let whole = dir.join("whole");
    let out = ok(&bake_args(whole.to_str().unwrap(), &[]));
    // The summary: what runs, how it did, and how to use it.
    for needle in [
        "linear design on sh:2 (siren), direct light traced (16 spp",
        "level calibrated",
        "checked on 2 held-out views",
        "against path tracing of its cost:",
        "level R / G / B",
        "nprt view ",
        "nprt render --model ",
    ] {
        assert!(out.contains(needle), "no '{needle}' in:\n{out}");
    }
    let model = whole.join("model");
    let config = std::fs::read_to_string(model.join("model.json")).unwrap();
    for needle in [
        r#""design": "linear""#,
        r#""basis": "sh:2""#,
        r#""direct": "traced""#,
    ] {
        assert!(config.contains(needle), "no {needle} in {config}");
    }
    assert!(config.contains("level_gain"), "{config}");
    for picture in ["preview.png", "comparison.png", "report/report.html"] {
        assert!(whole.join(picture).is_file(), "{picture}");
    }
    // The comparison is the model's frame, a gap, and the reference: twice as wide and more.
    let comparison = image::open(whole.join("comparison.png")).unwrap();
    assert_eq!((comparison.width(), comparison.height()), (2 * 24 + 4, 24));

    // Killed once its first relit frame is written, mid-training; the same command finishes
    // it to the weights of the run never killed.
    let killed = dir.join("killed");
    let k = killed.to_str().unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_nprt"))
        .args(bake_args(k, &[]))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let waited = Instant::now();
    while !killed.join("preview.png").is_file() {
        assert!(waited.elapsed().as_secs() < 300, "no preview was written");
        assert!(child.try_wait().unwrap().is_none(), "the bake ended early");
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !killed.join("comparison.png").exists(),
        "the run was not killed mid-way"
    );
    let out = ok(&bake_args(k, &[]));
    assert!(out.contains("model '"), "{out}");
    assert!(
        weights(&killed.join("model")) == weights(&model),
        "a killed and resumed bake's weights differ from an uninterrupted one's"
    );
    // Run again when done: nothing to do, the same answer.
    let again = ok(&bake_args(k, &[]));
    assert!(again.contains("level R / G / B"), "{again}");
    assert!(weights(&killed.join("model")) == weights(&model));
    // Another bake into the same folder is refused, naming both.
    fails(
        &bake_args(k, &["--seed", "1"]),
        &["holds another bake", "give another output folder"],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_scene_without_a_camera_volume_is_refused_with_the_flag_to_give_before_any_work() {
    let dir = fresh_dir("bake-no-volume");
    let out = dir.join("run");
    let mesh = assets().join("models/bunny.ply");
    fails(
        &[
            "bake",
            mesh.to_str().unwrap(),
            "--envmaps",
            "builtin",
            "--out",
            out.to_str().unwrap(),
            "--quality",
            "tiny",
        ],
        &["carries no camera volume", "--camera-volume"],
    );
    assert!(!out.exists(), "a refused bake made its folder");
    for (flag, value, needle) in [
        (
            "--minutes",
            "0",
            "--minutes 0 is not a number of minutes from 0.001",
        ),
        ("--quality", "fine", "choose draft, good or best"),
        // Maps that cannot be held out: refused before the folder is made, not after.
        (
            "--test-maps",
            "3",
            "--test-maps applies to a folder of maps",
        ),
    ] {
        let o = common::nprt(&[
            "bake",
            "builtin:room",
            "--envmaps",
            "builtin",
            "--out",
            out.to_str().unwrap(),
            flag,
            value,
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(needle), "{flag}: {err}");
    }
    assert!(!out.exists(), "a refused bake made its folder");
    let o = common::nprt(&bake_args("/dev/null", &[]));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--out '/dev/null' is not a folder"), "{err}");
}
