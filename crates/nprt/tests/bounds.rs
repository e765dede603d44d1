//! Hostile input, rounds three and four (issues 65 and 80): counts and sizes beyond the machine
//! refused before any work, by the flag (or variable) that asked for them, never a panic, an
//! abort or a run without end; numbers a run wrote read back as input; frames the GPU cannot
//! rasterise refused as such; a model folder cut between its two files refused, not rendered.

mod common;

use std::process::Command;

use common::{fails, fresh_dir, nprt, tiny_room_model};

/// `nprt eval` of a tiny model on its dataset with `extra` flags: what it prints on failure.
fn eval_fails(dir: &std::path::Path, extra: &[&str], needles: &[&str]) {
    let (data, model, out) = (dir.join("data"), dir.join("model"), dir.join("report"));
    let mut args = vec![
        "eval",
        "--data",
        data.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    fails(&args, needles);
    assert!(
        !out.join("results.json").exists(),
        "{extra:?} wrote results"
    );
}

#[test]
fn evaluation_counts_and_sizes_are_bounded_before_any_work() {
    let dir = fresh_dir("bounds-eval");
    tiny_room_model(&dir, &["--arch", "baseline"]);
    let huge = u64::MAX.to_string();
    for (flags, needle) in [
        (&["--temporal-frames", &huge][..], "--temporal-frames"),
        (&["--temporal-frames", "1000000000"], "more than the"),
        (
            &["--temporal-res", "4294967295"],
            "--temporal-res 4294967295",
        ),
        (&["--temporal-res", "100000"], "--temporal-res 100000"),
        (&["--nrc-warmup", "1000000000"], "--nrc-warmup 1000000000"),
        (&["--views", "0"], "--views must be at least 1"),
    ] {
        eval_fails(&dir, flags, &[needle]);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_batch_beyond_memory_is_refused_by_its_flag() {
    for size in [u64::MAX.to_string(), "1000000000000".to_string()] {
        fails(
            &[
                "bench",
                "train",
                "--arch",
                "baseline",
                "--batch-size",
                &size,
                "--steps",
                "1",
            ],
            &["--batch-size", "memory"],
        );
    }
}

#[test]
fn rayon_num_threads_is_held_to_the_threads_bound() {
    let o = Command::new(env!("CARGO_BIN_EXE_nprt"))
        .args(["model", "info", "--arch", "baseline"])
        .env("RAYON_NUM_THREADS", "100000")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("RAYON_NUM_THREADS 100000 is not in 1..="),
        "{err}"
    );
    let o = Command::new(env!("CARGO_BIN_EXE_nprt"))
        .args(["model", "info", "--arch", "baseline"])
        .env("RAYON_NUM_THREADS", "two")
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&o.stderr).contains("RAYON_NUM_THREADS='two'"));
    let o = Command::new(env!("CARGO_BIN_EXE_nprt"))
        .args(["model", "info", "--arch", "baseline"])
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .unwrap();
    assert!(o.status.success());
}

/// A checkpoint whose training time is not a time a run has is refused, not trained past its
/// budget.
#[test]
fn a_checkpoint_with_an_impossible_training_time_is_refused() {
    let dir = fresh_dir("bounds-seconds");
    let model = tiny_room_model(&dir, &["--arch", "baseline"]);
    let state = model.join("checkpoint/state.json");
    let text = std::fs::read_to_string(&state).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    for seconds in ["-1e308", "-0.5", "1e999"] {
        json["seconds"] = serde_json::json!("SECONDS");
        let forged = json.to_string().replace("\"SECONDS\"", seconds);
        std::fs::write(&state, forged).unwrap();
        let (data, out) = (dir.join("data"), model.to_str().unwrap().to_string());
        let args = [
            "train",
            "--data",
            data.to_str().unwrap(),
            "--arch",
            "baseline",
            "--out",
            &out,
            "--epochs",
            "2",
        ];
        let o = nprt(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{err}");
        assert!(
            err.contains("it says the run has trained") || err.contains("malformed"),
            "{err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A frame wider or taller than the GPU rasterises is refused by name on `--device wgpu`, as the
/// CPU route renders it, where its size is chosen: `generate` before its folder is made (so
/// before any training view is traced for a test size it cannot make), `render` and `eval`
/// before any frame.
#[cfg(feature = "gpu")]
#[test]
fn a_frame_beyond_the_gpus_texture_size_is_refused() {
    if !common::wgpu_runs() {
        return;
    }
    let dir = fresh_dir("bounds-texture");
    let model = tiny_room_model(&dir, &["--arch", "baseline"]);
    let (d, m) = (dir.join("data"), model.to_str().unwrap());
    let out = dir.join("wide");
    let o = out.to_str().unwrap();
    #[rustfmt::skip]
    fails(
        &["generate", "--scene", "builtin:room", "--envmaps", "builtin", "--out", o,
          "--train-views", "1", "--test-views", "1", "--train-res", "8", "--test-res", "1x20000",
          "--device", "wgpu"],
        &["20000", "pixels a side", "test view"],
    );
    assert!(
        !out.exists(),
        "generate made its folder before refusing the test size"
    );
    #[rustfmt::skip]
    fails(
        &["render", "--model", m, "--out", o, "--frames", "1", "--res", "16385x8",
          "--device", "wgpu"],
        &["16385", "pixels a side"],
    );
    #[rustfmt::skip]
    fails(
        &["eval", "--data", d.to_str().unwrap(), "--model", m, "--out", o,
          "--temporal-frames", "2", "--temporal-res", "16385", "--device", "wgpu"],
        // Square: the memory check may speak first; either names the flag.
        &["--temporal-res 16385"],
    );
    assert!(!out.exists(), "a refused frame size left output behind");
    std::fs::remove_dir_all(&dir).ok();
    for (res, side) in [("16385x1", "16385"), ("1x20000", "20000")] {
        fails(
            &[
                "bench",
                "frame",
                "--arch",
                "baseline",
                "--res",
                res,
                "--repeats",
                "1",
                "--direct-spp",
                "0",
                "--device",
                "wgpu",
            ],
            &[side, "pixels a side"],
        );
    }
}

/// A dataset whose manifest records a camera volume `generate` would refuse is refused where
/// it is read, by the same rule, not evaluated along a path through it.
#[test]
fn a_manifest_camera_volume_is_checked_as_generate_checks_it() {
    let dir = fresh_dir("bounds-volume");
    tiny_room_model(&dir, &["--arch", "baseline"]);
    let manifest = dir.join("data/manifest.json");
    let kept = std::fs::read_to_string(&manifest).unwrap();
    let json: serde_json::Value = serde_json::from_str(&kept).unwrap();
    let volume = &json["settings"]["camera_volume"];
    for (field, value, rule) in [
        ("min", serde_json::json!([9.0, 9.0, 9.0]), "must not exceed"),
        (
            "look",
            serde_json::json!([0.0, 0.0, 0.0]),
            "non-zero direction",
        ),
        ("fov_deg", serde_json::json!(0.0), "fov_deg"),
        ("fov_deg", serde_json::json!(-5.0), "fov_deg"),
        ("spread_deg", serde_json::json!(90.0), "spread_deg"),
        ("max", serde_json::json!([1e30, 1e30, 1e30]), "within ±10⁶"),
    ] {
        let mut edited = json.clone();
        edited["settings"]["camera_volume"][field] = value;
        assert_ne!(&edited["settings"]["camera_volume"], volume);
        std::fs::write(&manifest, edited.to_string()).unwrap();
        eval_fails(&dir, &[], &["camera_volume", rule]);
    }
    std::fs::write(&manifest, kept).unwrap();
    std::fs::remove_dir_all(&dir).ok();
}

/// Weights with a value no trained network holds (finite, 10³⁰) are refused where they load,
/// not rendered into black frames or exported with an all-zero reference.
#[test]
fn weights_of_an_implausible_magnitude_are_refused_on_load() {
    use nprt_net::model::folder::{load_model, save_model};
    use nprt_net::Parameters;
    let dir = fresh_dir("bounds-weights");
    let model = tiny_room_model(&dir, &["--arch", "baseline"]);
    let (file, mut net) = load_model(&model).unwrap();
    let mut first = true;
    net.visit_mut("", &mut |_, _, values| {
        if std::mem::take(&mut first) {
            values[0] = 1e30;
        }
    });
    save_model(&model, &file, &net).unwrap();
    let frames = dir.join("frames");
    for args in [
        &[
            "render",
            "--model",
            model.to_str().unwrap(),
            "--out",
            frames.to_str().unwrap(),
        ][..],
        &[
            "export",
            model.to_str().unwrap(),
            "--out",
            frames.to_str().unwrap(),
        ],
    ] {
        let o = nprt(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("holds 1e30") && err.contains("damaged"),
            "{err}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Reflectances outside [0, 1] (a negative value, a bitmap's negative texels, a blend weight of
/// 2) are held to [0, 1] with a warning, as maps are: the dataset they make verifies.
#[test]
fn reflectances_outside_the_unit_range_are_clamped_with_a_warning() {
    let dir = fresh_dir("bounds-reflectance");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("odd.xml");
    std::fs::write(
        &scene,
        r#"<scene version="3.0.0">
  <shape type="cube"><bsdf type="diffuse"><rgb name="reflectance" value="-1, 0.5, 2"/></bsdf></shape>
  <shape type="rectangle"><bsdf type="blendbsdf"><float name="weight" value="2"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>
    <bsdf type="roughconductor"><float name="alpha" value="0.2"/><string name="material" value="none"/></bsdf>
  </bsdf></shape>
</scene>"#,
    )
    .unwrap();
    std::fs::write(
        dir.join("odd.camera.json"),
        r#"{"min": [-3, 0, 2], "max": [3, 1, 3], "look": [0, 0, -1], "spread_deg": 10, "fov_deg": 50}"#,
    )
    .unwrap();
    let data = dir.join("data");
    let o = nprt(&[
        "generate",
        "--scene",
        scene.to_str().unwrap(),
        "--envmaps",
        "builtin",
        "--out",
        data.to_str().unwrap(),
        "--train-views",
        "2",
        "--test-views",
        "1",
        "--train-res",
        "8",
        "--test-res",
        "8",
        "--spp",
        "2",
        "--test-spp",
        "2",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("diffuse reflectance goes outside [0, 1]"),
        "{err}"
    );
    assert!(err.contains("blend weight 2 is outside [0, 1]"), "{err}");
    let o = nprt(&["dataset", "verify", data.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
    std::fs::remove_dir_all(&dir).ok();
}

/// Every flag that takes a number refuses NaN and infinity by name, as clap's own float
/// parsers do not (a NaN turn made an all-NaN frame, an infinite learning rate a NaN model).
#[test]
fn number_flags_refuse_nan_and_infinity() {
    #[rustfmt::skip]
    let cases: [&[&str]; 6] = [
        &["reference", "builtin:room", "--out", "x.exr", "--rotate", "nan"],
        &["generate", "--scene", "builtin:room", "--envmaps", "builtin", "--out", "d", "--jitter-exposure", "inf"],
        &["generate", "--scene", "builtin:room", "--envmaps", "builtin", "--out", "d", "--look", "0,nan,1"],
        &["train", "--data", "d", "--arch", "dsep", "--out", "m", "--lr", "NaN"],
        &["render", "--model", "m", "--out", "o", "--spin=-inf"],
        &["train", "--data", "d", "--arch", "dsep", "--out", "m", "--minutes", "inf"],
    ];
    for args in cases {
        let o = nprt(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("finite"), "{args:?}: {err}");
    }
}

/// `nprt train --out` naming the dataset folder is refused before any model file is written
/// there (the training pack, the dataset's own, may be made first).
#[test]
fn a_model_is_not_written_into_its_dataset() {
    let dir = fresh_dir("bounds-model-into-data");
    let data = dir.join("data");
    common::room_dataset(&data, [4, 1], 8, 2);
    let d = data.to_str().unwrap();
    fails(
        &[
            "train", "--data", d, "--arch", "baseline", "--epochs", "1", "--out", d,
        ],
        &["is a dataset folder"],
    );
    for model_file in [
        "model.json",
        "weights.safetensors",
        "checkpoint",
        "loss.csv",
        ".lock",
    ] {
        assert!(
            !data.join(model_file).exists(),
            "{model_file} written into the dataset"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// An evaluation over one test view with a temporal path of two frames (one frame pair) has no
/// spread to show: its report prints each mean without ± and no NaN or infinity anywhere (it
/// printed "± NaN" and "± inf").
#[test]
fn a_report_over_one_view_and_one_frame_pair_shows_no_nan_or_infinity() {
    let dir = fresh_dir("bounds-one-view");
    let model = tiny_room_model(&dir, &["--arch", "baseline"]);
    let (data, out) = (dir.join("data"), dir.join("report"));
    #[rustfmt::skip]
    common::ok(&[
        "eval", "--data", data.to_str().unwrap(), "--model", model.to_str().unwrap(),
        "--out", out.to_str().unwrap(), "--views", "1", "--timing-res", "8", "--sh-spp", "1",
        "--temporal-frames", "2", "--temporal-res", "8",
    ]);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    let words: Vec<&str> = md.split(|c: char| !c.is_alphanumeric()).collect();
    for bad in ["nan", "inf"] {
        assert!(
            !words.iter().any(|w| w.eq_ignore_ascii_case(bad)),
            "report.md shows {bad}:\n{md}"
        );
    }
    assert!(md.contains("1 test view"), "{md}");
    assert!(md.contains("no spread"), "{md}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A model folder's numbers are checked where it is read, by every command: a level gain no
/// calibration makes (10³⁰, 0, −1: rendered, exported and evaluated with exit 0) is refused
/// naming the channel and the range; weights written without their model.json (a save cut
/// between the two) are refused as incomplete; `generate --out` refuses the model folder.
#[test]
fn a_model_folder_s_gain_and_wholeness_are_checked_where_it_is_read() {
    use nprt_net::model::folder::{load_model, save_weights, WEIGHTS_FILE};
    use nprt_net::Parameters;
    let dir = fresh_dir("bounds-gain");
    let model = tiny_room_model(&dir, &["--arch", "baseline"]);
    let m = model.to_str().unwrap();
    let config = model.join("model.json");
    let kept = std::fs::read_to_string(&config).unwrap();
    let json: serde_json::Value = serde_json::from_str(&kept).unwrap();
    assert!(json["weights_blake3"].is_string(), "{json}");
    let frames = dir.join("frames");
    let commands: [Vec<&str>; 3] = [
        vec!["render", "--model", m, "--out", frames.to_str().unwrap()],
        vec!["export", m, "--out", frames.to_str().unwrap()],
        vec!["model", "info", "--model", m],
    ];
    for (gain, said) in [
        (
            serde_json::json!([1e30, 1.0, 1.0]),
            "level_gain's R is 1e30",
        ),
        (serde_json::json!([1.0, 0.0, 1.0]), "level_gain's G is 0,"),
        (serde_json::json!([1.0, 1.0, -1.0]), "level_gain's B is -1,"),
    ] {
        let mut edited = json.clone();
        edited["level_gain"] = gain;
        std::fs::write(&config, edited.to_string()).unwrap();
        for args in &commands {
            fails(args, &[said, "outside the 0.001 to 1000"]);
        }
        eval_fails(&dir, &[], &[said]);
    }
    std::fs::write(&config, &kept).unwrap();
    // The weights of a later save, without the model.json that names them.
    let (file, mut net) = load_model(&model).unwrap();
    net.visit_mut("", &mut |_, _, values| values[0] += 0.25);
    save_weights(&model.join(WEIGHTS_FILE), &net, &file.config.weights_tag()).unwrap();
    for args in &commands[..2] {
        fails(args, &["is incomplete", "run the training again"]);
    }
    let o = nprt(&[
        "generate",
        "--scene",
        "builtin:room",
        "--envmaps",
        "builtin",
        "--out",
        m,
        "--train-views",
        "2",
        "--test-views",
        "1",
        "--train-res",
        "8",
        "--test-res",
        "8",
        "--spp",
        "1",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("is a model folder (it holds model.json)"),
        "{err}"
    );
    assert!(!model.join("manifest.json").exists() && !model.join("views").exists());
    std::fs::remove_dir_all(&dir).ok();
}
