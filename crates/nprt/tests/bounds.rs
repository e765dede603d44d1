//! Hostile input, round three (issue 65): counts and sizes beyond the machine refused before
//! any work, by the flag (or variable) that asked for them, never a panic, an abort or a run
//! without end; numbers a run wrote read back as input; frames the GPU cannot rasterise refused
//! as such.

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
    assert!(!out.join("results.json").exists(), "{extra:?} wrote results");
}

#[test]
fn evaluation_counts_and_sizes_are_bounded_before_any_work() {
    let dir = fresh_dir("bounds-eval");
    tiny_room_model(&dir, "baseline", &[]);
    let huge = u64::MAX.to_string();
    for (flags, needle) in [
        (&["--temporal-frames", &huge][..], "--temporal-frames"),
        (&["--temporal-frames", "1000000000"], "more than the"),
        (&["--temporal-res", "4294967295"], "--temporal-res 4294967295"),
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
            &["bench", "train", "--arch", "baseline", "--batch-size", &size, "--steps", "1"],
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
    assert!(err.contains("RAYON_NUM_THREADS 100000 is not in 1..="), "{err}");
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
    let model = tiny_room_model(&dir, "baseline", &[]);
    let state = model.join("checkpoint/state.json");
    let text = std::fs::read_to_string(&state).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    for seconds in ["-1e308", "-0.5", "1e999"] {
        json["seconds"] = serde_json::json!("SECONDS");
        let forged = json.to_string().replace("\"SECONDS\"", seconds);
        std::fs::write(&state, forged).unwrap();
        let (data, out) = (dir.join("data"), model.to_str().unwrap().to_string());
        let args = [
            "train", "--data", data.to_str().unwrap(), "--arch", "baseline", "--out", &out,
            "--epochs", "2",
        ];
        let o = nprt(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{err}");
        assert!(err.contains("which no run has") || err.contains("malformed"), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A frame wider or taller than the GPU rasterises is refused by name on `--device wgpu`, as the
/// CPU route renders it.
#[cfg(feature = "gpu")]
#[test]
fn a_frame_beyond_the_gpus_texture_size_is_refused() {
    if !common::wgpu_runs() {
        return;
    }
    for (res, side) in [("16385x1", "16385"), ("1x20000", "20000")] {
        fails(
            &[
                "bench", "frame", "--arch", "baseline", "--res", res, "--repeats", "1",
                "--direct-spp", "0", "--device", "wgpu",
            ],
            &[side, "pixels a side"],
        );
    }
}
