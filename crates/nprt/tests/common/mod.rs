//! Helpers shared by the integration tests that drive the `nprt` binary.
#![allow(dead_code, unused_imports)] // each test file uses its own subset

// Shared with nprt-trace's tests of the tracer on the device.
#[path = "../../../nprt-trace/tests/common/frame_noise.rs"]
mod frame_noise;
#[path = "../../../nprt-trace/tests/common/shared_data.rs"]
mod shared_data;
pub use frame_noise::{block_rms, trimmed_block_rms};
pub use shared_data::{repo, shared};

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn nprt(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nprt"))
        .args(args)
        .output()
        .expect("run nprt")
}

/// Runs one of the repository's bash scripts (`path` from the repository's root).
pub fn script(path: &str, args: &[&str]) -> Output {
    Command::new("bash")
        .arg(repo().join(path))
        .args(args)
        .output()
        .expect("run bash")
}

/// Runs nprt expecting success; returns stdout.
pub fn ok(args: &[&str]) -> String {
    let o = nprt(args);
    assert!(
        o.status.success(),
        "{args:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Runs nprt expecting exit 1 without a panic, with every `needle` in stderr.
pub fn fails(args: &[&str], needles: &[&str]) {
    let o = nprt(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(1),
        "expected exit 1 for {args:?}; stderr: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "stderr for {args:?} lacks '{n}':\n{err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

/// A dataset of builtin:room under built-in lighting in `dir`: `[train, test]` views of
/// `res`², training views at `spp` samples per pixel, test views at twice that.
pub fn room_dataset(dir: &Path, [train, test]: [u32; 2], res: u32, spp: u32) {
    let [train, test, res, spp, test_spp] = [train, test, res, spp, 2 * spp].map(|n| n.to_string());
    ok(&[
        "generate",
        "--scene",
        "builtin:room",
        "--envmaps",
        "builtin",
        "--out",
        dir.to_str().unwrap(),
        "--train-views",
        &train,
        "--test-views",
        &test,
        "--train-res",
        &res,
        "--test-res",
        &res,
        "--spp",
        &spp,
        "--test-spp",
        &test_spp,
    ]);
}

/// A model trained for one epoch on a tiny room dataset, both made in `dir`, with `flags` added
/// to `nprt train` (`--arch DESIGN`, or none for the recommended recipe): what tests of the
/// commands that read a model start from.
pub fn tiny_room_model(dir: &Path, flags: &[&str]) -> PathBuf {
    let data = dir.join("data");
    room_dataset(&data, [8, 2], 16, 4);
    let model = dir.join("model");
    let (d, m) = (data.to_str().unwrap(), model.to_str().unwrap());
    let mut args = vec!["train", "--data", d, "--out", m, "--epochs", "1"];
    args.extend_from_slice(flags);
    ok(&args);
    model
}

/// A fresh, empty (not yet created) folder path unique to this test process.
pub fn fresh_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("nprt-it-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// The repository's small test assets (env maps, meshes; see tests/assets/README.md).
pub fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/assets")
}

/// One tiny frame benchmark (an 8×8 frame of the baseline design) on `device`.
pub fn tiny_frame(device: &str) -> Output {
    nprt(&[
        "bench",
        "frame",
        "--arch",
        "baseline",
        "--res",
        "8",
        "--repeats",
        "1",
        "--direct-spp",
        "0",
        "--device",
        device,
    ])
}

/// Whether `--device wgpu` runs here (a Vulkan driver, e.g. the software one scripts/vulkan.sh
/// installs). Where NPRT_REQUIRE_VULKAN is set (scripts/test sets it) it must. Asked once per
/// test binary: each asking starts the device and compiles its kernels.
pub fn wgpu_runs() -> bool {
    static RUNS: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *RUNS.get_or_init(wgpu_runs_once)
}

fn wgpu_runs_once() -> bool {
    let o = tiny_frame("wgpu");
    let err = String::from_utf8_lossy(&o.stderr);
    if o.status.success() {
        return true;
    }
    assert!(
        std::env::var_os("NPRT_REQUIRE_VULKAN").is_none(),
        "NPRT_REQUIRE_VULKAN is set but --device wgpu failed: {err}"
    );
    let why = if cfg!(feature = "gpu") {
        "no GPU adapter found"
    } else {
        "this nprt was built without its GPU kernels"
    };
    assert!(err.contains(why), "{err}");
    eprintln!("skipped: {err}");
    false
}
