//! Hostile input and odd paths (issue 36), as a demanding new user tries them: outputs that
//! are not plain files, results that would be NaN or black, sizes beyond the machine, and
//! datasets broken in ways a verifier must see. Every case ends in a clear error or a warning,
//! never a panic, a replaced device or a non-finite file written with exit 0.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use common::{fails, fresh_dir, nprt, ok};
use nprt_io::exr::{read_channels, write_channels};

/// A tiny dataset of builtin:room (4 + 2 views of 8×8) in `dir`.
fn tiny_dataset(dir: &Path) {
    common::room_dataset(dir, [4, 2], 8, 1);
}

/// A fresh folder `name` holding a tiny dataset in `ds`: (folder, dataset).
fn with_dataset(name: &str) -> (PathBuf, PathBuf) {
    let dir = fresh_dir(name);
    let data = dir.join("ds");
    tiny_dataset(&data);
    (dir, data)
}

/// A fresh folder `name` holding a tiny dataset (`ds`) and a model trained on it for one epoch
/// with `extra` flags (`model`): (folder, dataset, model).
fn trained_model(name: &str, extra: &[&str]) -> (PathBuf, PathBuf, PathBuf) {
    let (dir, data) = with_dataset(name);
    let model = dir.join("model");
    let mut flags = vec!["--epochs", "1"];
    flags.extend_from_slice(extra);
    ok(&train_args(
        data.to_str().unwrap(),
        model.to_str().unwrap(),
        &flags,
    ));
    (dir, data, model)
}

fn train_args<'a>(data: &'a str, out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "train",
        "--data",
        data,
        "--arch",
        "baseline",
        "--out",
        out,
        "--encoder-width",
        "64",
    ];
    args.extend_from_slice(extra);
    args
}

/// `nprt reference` of builtin:room at 8×8, 1 spp, into `out`.
fn reference_args(out: &Path) -> Vec<&str> {
    vec![
        "reference",
        "builtin:room",
        "--envmap",
        "builtin:sky",
        "--spp",
        "1",
        "--width",
        "8",
        "--height",
        "8",
        "--out",
        out.to_str().unwrap(),
    ]
}

/// `nprt render` of `model`: `frames` 8×8 frames with linear EXRs into `out`, with `extra`.
fn render_exr(model: &str, out: &Path, frames: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "render",
        "--model",
        model,
        "--frames",
        frames,
        "--res",
        "8",
        "--exr",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    nprt(&args)
}

/// Starts a training run on `out` that lasts until killed.
fn endless_training(data: &str, out: &str) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_nprt"))
        .args(train_args(data, out, &["--epochs", "100000"]))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

#[cfg(unix)]
#[test]
fn outputs_through_links_are_written_through_and_special_files_never_replaced() {
    use std::os::unix::fs::FileTypeExt;
    let dir = fresh_dir("odd-outputs");
    std::fs::create_dir_all(&dir).unwrap();
    // A link: the file it points to is written, the link stays a link.
    let target = dir.join("target.exr");
    let link = dir.join("link.exr");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    ok(&reference_args(&link));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(read_channels(&target).unwrap().0, 8);
    // A FIFO and a device are refused and left as they were.
    let fifo = dir.join("fifo.exr");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    for (path, kind) in [
        (fifo.as_path(), "a FIFO"),
        (Path::new("/dev/full"), "a device"),
    ] {
        let out = path.to_str().unwrap();
        fails(&reference_args(path), &[out, kind, "not a regular file"]);
    }
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
    assert!(std::fs::symlink_metadata("/dev/full")
        .unwrap()
        .file_type()
        .is_char_device());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Writes a 2:1 Radiance HDR map of one value.
fn flat_map(path: &Path, value: f32) {
    image::Rgb32FImage::from_pixel(16, 8, image::Rgb([value; 3]))
        .save(path)
        .unwrap();
}

#[test]
fn non_finite_results_are_refused_and_black_lighting_is_warned_of() {
    let (dir, data) = with_dataset("nan");
    let d = data.to_str().unwrap();
    // A learning rate that breaks the weights: the run stops with exit 1 (it saved a model
    // with a non-finite validation loss and exit 0) and removes the model files it saved at
    // every step's checkpoint (weights of 1e30, finite, rendered black frames with exit 0), so
    // render refuses the folder. The broken weights make infinite radiance on the CPU engine
    // (exp overflows).
    let blown = dir.join("blown");
    let b = blown.to_str().unwrap();
    let every_step = ["--lr", "1e30", "--epochs", "2", "--checkpoint-minutes", "0"];
    fails(
        &train_args(d, b, &every_step),
        &[
            "training diverged",
            "validation loss inf",
            "its model files are removed",
            "lower --lr",
        ],
    );
    assert!(!blown.join("model.json").exists() && !blown.join("weights.safetensors").exists());
    let rendered = render_exr(b, &dir.join("blown-frames"), "1", &[]);
    assert_eq!(rendered.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&rendered.stderr).contains("is not a model folder"));

    // A camera path keyframe straight above its target renders finite frames.
    let model = dir.join("model");
    let m = model.to_str().unwrap();
    ok(&train_args(d, m, &["--epochs", "1"]));
    let path = dir.join("up.json");
    std::fs::write(
        &path,
        r#"{"keyframes": [{"position": [0, 1, 1], "target": [0, 2, 1]}, {"position": [0, 1, 1], "target": [0, 2, 1]}]}"#,
    )
    .unwrap();
    let frames = dir.join("frames");
    let up = render_exr(m, &frames, "2", &["--camera-path", path.to_str().unwrap()]);
    assert!(
        up.status.success(),
        "{}",
        String::from_utf8_lossy(&up.stderr)
    );
    let (_, _, ch) = read_channels(&frames.join("frames/0000.exr")).unwrap();
    assert!(ch["R"].iter().all(|v| v.is_finite()));

    // A map at the top of Radiance HDR's exponent range (everything rendered infinite) is
    // refused; an all-black map is warned of.
    let maps = dir.join("maps");
    std::fs::create_dir_all(&maps).unwrap();
    let huge = dir.join("huge.hdr");
    flat_map(&huge, 1e38);
    fails(
        &[
            "reference",
            "builtin:room",
            "--envmap",
            huge.to_str().unwrap(),
            "--out",
            dir.join("x.exr").to_str().unwrap(),
        ],
        &["huge.hdr", "not a finite radiance of at most 1e12"],
    );
    flat_map(&maps.join("black.hdr"), 0.0);
    flat_map(&maps.join("white.hdr"), 1.0);
    let out = nprt(&[
        "generate",
        "--scene",
        "builtin:room",
        "--envmaps",
        maps.to_str().unwrap(),
        "--mix-builtin",
        "0",
        "--out",
        dir.join("dark").to_str().unwrap(),
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
        "--test-spp",
        "2",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("warning: environment map") && err.contains("black.hdr' is black everywhere"),
        "{err}"
    );

    // Test views whose camera is all zeros (NaN metrics before) are refused by every command.
    let manifest = data.join("manifest.json");
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&manifest).unwrap()).unwrap();
    let test = json["views"]
        .as_array()
        .unwrap()
        .iter()
        .position(|v| v["split"] == "test")
        .unwrap();
    json["views"][test]["camera_to_world"] = serde_json::json!(vec![0.0; 16]);
    std::fs::write(&manifest, serde_json::to_vec(&json).unwrap()).unwrap();
    fails(
        &[
            "eval",
            "--data",
            d,
            "--model",
            m,
            "--out",
            dir.join("report").to_str().unwrap(),
        ],
        &["manifest.json", "camera_to_world is not a rotation"],
    );
    assert!(!dir.join("report").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn sizes_beyond_the_machine_are_refused_before_allocating() {
    let (dir, data) = with_dataset("sizes");
    let d = data.to_str().unwrap();
    let out = dir.join("o");
    let o = out.to_str().unwrap();
    let started = std::time::Instant::now();
    fails(
        &[
            "generate",
            "--scene",
            "builtin:room",
            "--envmaps",
            "builtin",
            "--out",
            o,
            "--train-views",
            "1000000000000",
        ],
        &[
            "planning 1000000000040 views needs",
            "GiB",
            "available here",
        ],
    );
    fails(
        &[
            "reference",
            "builtin:room",
            "--envmap",
            "builtin:sky",
            "--width",
            "100000",
            "--height",
            "100000",
            "--out",
            &format!("{o}.exr"),
        ],
        &["a 100000×100000 frame needs"],
    );
    fails(
        &train_args(d, o, &["--encoder-width", "6400000"]),
        &["encoder input width 6400000", "to 1024"],
    );
    fails(
        &["--threads", "100000", "dataset", "verify", d],
        &["--threads 100000 is not in 1..="],
    );
    let model = dir.join("model");
    ok(&train_args(d, model.to_str().unwrap(), &["--epochs", "1"]));
    fails(
        &[
            "render",
            "--model",
            model.to_str().unwrap(),
            "--res",
            "100000",
            "--out",
            o,
        ],
        &["a 100000×100000 frame needs"],
    );
    assert!(!out.exists());
    // Refused at once, not after growing for minutes (a generous bound: debug builds, busy CI).
    assert!(started.elapsed().as_secs() < 120);
    let deep = dir.join("deep.xml");
    std::fs::write(
        &deep,
        format!(
            r#"<scene version="3.0.0"><shape type="cube">{}<bsdf type="diffuse"/>{}</shape></scene>"#,
            r#"<bsdf type="twosided">"#.repeat(3000),
            "</bsdf>".repeat(3000)
        ),
    )
    .unwrap();
    fails(
        &[
            "reference",
            deep.to_str().unwrap(),
            "--envmap",
            "builtin:sky",
            "--out",
            &format!("{o}.exr"),
        ],
        &["deep.xml:1:", "more than 100 levels"],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The path of the first view of `split` in the dataset `data`.
fn view_file(data: &Path, split: &str) -> PathBuf {
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(data.join("manifest.json")).unwrap()).unwrap();
    let view = json["views"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["split"] == split)
        .unwrap();
    data.join(view["file"].as_str().unwrap())
}

#[test]
fn verify_reports_bad_texels_and_leftovers_and_train_names_the_pixel() {
    let (dir, data) = with_dataset("verify");
    let d = data.to_str().unwrap();
    // A negative radiance texel: verify calls the view corrupt and train names file and pixel
    // (instead of diverging and blaming --lr).
    let view = view_file(&data, "train");
    let (w, h, mut ch) = read_channels(&view).unwrap();
    let original = std::fs::read(&view).unwrap();
    ch.get_mut("G").unwrap()[2 * w + 5] = -0.5;
    let channels: Vec<(String, Vec<f32>)> = ch.into_iter().collect();
    write_channels(&view, w, h, &channels).unwrap();
    let name = view.file_name().unwrap().to_str().unwrap();
    let o = nprt(&["dataset", "verify", d]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stdout.contains(&format!("corrupt: views/{name}"))
            && stdout.contains("channel 'G' is -0.5 at pixel (5, 2), but cannot be negative"),
        "{stdout}"
    );
    let model = dir.join("model");
    fails(
        &train_args(d, model.to_str().unwrap(), &["--epochs", "1"]),
        &[name, "channel 'G' is -0.5 at pixel (5, 2)"],
    );
    // A reflectance or α of 1e30 (finite, past the G-buffer's [0, 1]) or a radiance of 1e30
    // (past the largest a map may hold) likewise, where train blamed --lr.
    for channel in ["kd.G", "alpha", "B"] {
        let (w, h, mut ch) = read_channels(&view).unwrap();
        ch.get_mut("G").unwrap()[2 * w + 5] = 0.5;
        ch.get_mut(channel).unwrap()[w + 3] = 1e30;
        let channels: Vec<(String, Vec<f32>)> = ch.into_iter().collect();
        write_channels(&view, w, h, &channels).unwrap();
        let range = if channel == "B" { "1e12" } else { "1" };
        let why = format!(
            "channel '{channel}' is 1000000000000000000000000000000 at pixel (3, 1), outside [0, {range}]"
        );
        let o = nprt(&["dataset", "verify", d]);
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert_eq!(o.status.code(), Some(1));
        assert!(stdout.contains(&why), "{stdout}");
        fails(
            &train_args(d, model.to_str().unwrap(), &["--epochs", "1"]),
            &[name, &why],
        );
        std::fs::write(&view, &original).unwrap();
    }
    // A temporary file a killed run left: verify reports it, a re-run of generate removes it.
    let leftover = view.with_file_name(format!(".{name}.4242.tmp"));
    std::fs::write(&leftover, b"half a view").unwrap();
    let report = ok(&["dataset", "verify", d]);
    assert!(
        report.contains("leftover:") && report.contains(".4242.tmp"),
        "{report}"
    );
    tiny_dataset(&data);
    assert!(!leftover.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_second_training_run_on_one_folder_is_refused_by_name() {
    let (dir, data) = with_dataset("lock");
    let d = data.to_str().unwrap();
    let out = dir.join("model");
    let o = out.to_str().unwrap();
    let mut first = endless_training(d, o);
    let lock = out.join(".lock");
    let waited = std::time::Instant::now();
    while !std::fs::read_to_string(&lock).is_ok_and(|s| s.starts_with("pid")) {
        assert!(
            waited.elapsed().as_secs() < 120,
            "the first run never took the lock"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    fails(
        &train_args(d, o, &["--epochs", "1"]),
        &[
            "model folder",
            "is in use by another run",
            &format!("pid {}", first.id()),
        ],
    );
    first.kill().unwrap();
    first.wait().unwrap();
    // The lock dies with its process: the next run takes it.
    let mut next = endless_training(d, o);
    let holder = format!("pid {}", next.id());
    while std::fs::read_to_string(&lock).ok().as_deref() != Some(holder.as_str()) {
        assert!(
            waited.elapsed().as_secs() < 240,
            "the lock was not released"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    next.kill().unwrap();
    next.wait().unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Lock files made links to other files are refused by kind and their targets left intact
/// (the model folder's `.lock` had its target overwritten with a pid, the dataset's
/// `.packing.lock` had its target truncated to 0 bytes).
#[cfg(unix)]
#[test]
fn lock_files_are_never_followed() {
    let (dir, data) = with_dataset("lock-links");
    let d = data.to_str().unwrap();
    let precious = dir.join("precious.txt");
    std::fs::write(&precious, b"keep me").unwrap();
    let out = dir.join("model");
    std::fs::create_dir_all(&out).unwrap();
    std::os::unix::fs::symlink(&precious, out.join(".lock")).unwrap();
    let o = out.to_str().unwrap();
    fails(
        &train_args(d, o, &["--epochs", "1"]),
        &["lock file", ".lock", "is a symbolic link"],
    );
    std::fs::remove_file(out.join(".lock")).unwrap();
    // The first run packed the dataset before it took the model folder's lock: unpacked
    // again, the next run must take the packing lock.
    for entry in std::fs::read_dir(&data).unwrap().flatten() {
        if entry.file_name().to_string_lossy().starts_with("packed-") {
            std::fs::remove_file(entry.path()).unwrap();
        }
    }
    std::fs::remove_file(data.join(".packing.lock")).ok();
    std::os::unix::fs::symlink(&precious, data.join(".packing.lock")).unwrap();
    fails(
        &train_args(d, o, &["--epochs", "1"]),
        &[".packing.lock", "is a symbolic link"],
    );
    assert_eq!(std::fs::read(&precious).unwrap(), b"keep me");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs nprt expecting exit 1 within a minute, with every `needle` in its output (a report on
/// stdout, or stderr): a command that blocks is killed and the test fails, instead of hanging
/// the suite.
fn fails_in_time(args: &[&str], needles: &[&str]) {
    let (code, err) = run_in_time(args);
    assert_eq!(code, Some(1), "{args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "stderr for {args:?} lacks '{n}':\n{err}");
    }
}

/// Runs nprt with `args`, killing it and failing the test if it takes over a minute; returns
/// its exit status and what it printed (stderr, then stdout).
fn run_in_time(args: &[&str]) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_nprt"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed().as_secs() > 60 {
            child.kill().ok();
            panic!("{args:?} blocked for a minute");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let out = child.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&out.stderr) + String::from_utf8_lossy(&out.stdout);
    (out.status.code(), text.into_owned())
}

/// Makes `path` a FIFO (nothing ever writes to it: opening it to read would block for ever).
#[cfg(unix)]
fn make_fifo(path: &Path) {
    std::fs::remove_file(path).ok();
    let status = Command::new("mkfifo").arg(path).status().unwrap();
    assert!(status.success());
}

/// Inputs that are FIFOs (a view file, a model's weights, an environment map, the packing
/// lock), which blocked `dataset verify`, `model info`, `reference` and `train` for ever, are
/// refused by kind at once.
#[cfg(unix)]
#[test]
fn fifos_given_as_inputs_are_refused_without_blocking() {
    let (dir, data, model) = trained_model("fifos", &[]);
    let (d, m) = (data.to_str().unwrap(), model.to_str().unwrap());
    make_fifo(&model.join("weights.safetensors"));
    fails_in_time(
        &["model", "info", "--model", m],
        &["weights.safetensors", "is a FIFO"],
    );
    let map = dir.join("map.exr");
    make_fifo(&map);
    let out = dir.join("ref");
    let mut args = reference_args(&out);
    args[3] = map.to_str().unwrap();
    fails_in_time(&args, &["map.exr", "is a FIFO"]);
    make_fifo(&data.join(".packing.lock"));
    std::fs::remove_file(data.join("packed-radiance.bin")).ok();
    let again = dir.join("again");
    fails_in_time(
        &train_args(d, again.to_str().unwrap(), &["--epochs", "1"]),
        &[".packing.lock", "is a FIFO"],
    );
    make_fifo(&view_file(&data, "train"));
    fails_in_time(&["dataset", "verify", d], &["is a FIFO"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Geometry the tracer cannot hold is refused when the scene loads, before the BVH is built:
/// a rectangle scaled by 3e38 panicked inside the builder, a sphere of radius 1e30 looped in it.
#[test]
fn geometry_beyond_the_stated_range_is_refused_before_the_bvh() {
    let dir = fresh_dir("far");
    std::fs::create_dir_all(&dir).unwrap();
    for (name, shape) in [
        (
            "scaled",
            r#"<shape type="rectangle"><transform name="to_world"><scale value="3e38"/></transform></shape>"#,
        ),
        (
            "sphere",
            r#"<shape type="sphere"><float name="radius" value="1e30"/></shape>"#,
        ),
        (
            "negative",
            r#"<shape type="sphere"><float name="radius" value="-1e38"/></shape>"#,
        ),
    ] {
        let scene = dir.join(format!("{name}.xml"));
        std::fs::write(&scene, format!(r#"<scene version="3.0.0">{shape}</scene>"#)).unwrap();
        let out = dir.join(name);
        let mut args = reference_args(&out);
        args[1] = scene.to_str().unwrap();
        fails_in_time(&args, &[&format!("{name}.xml"), "beyond ±1e9 scene units"]);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A test view whose reference holds no light (lit by a black map) leaves the light level and
/// tint undefined: eval stops naming the view instead of writing `null` into results.json.
#[test]
fn a_black_test_view_stops_eval_naming_it() {
    let (dir, data, model) = trained_model("black-test", &[]);
    let view = view_file(&data, "test");
    let (w, h, mut channels) = read_channels(&view).unwrap();
    for (name, values) in &mut channels {
        if ["R", "G", "B"].contains(&name.as_str()) || name.starts_with("half.") {
            values.fill(0.0);
        }
    }
    let mut channels: Vec<(String, Vec<f32>)> = channels.into_iter().collect();
    channels.sort_by(|a, b| a.0.cmp(&b.0));
    write_channels(&view, w, h, &channels).unwrap();
    let report = dir.join("report");
    let args = [
        "eval",
        "--data",
        data.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
        "--out",
        report.to_str().unwrap(),
        "--sh-spp",
        "4",
        "--timing-res",
        "16",
    ];
    fails(
        &args,
        &["tint error", "holds no light", "no report is written"],
    );
    assert!(!report.join("results.json").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A lighting schedule of 10⁴ segments of one map opens that map once (opened per segment, it
/// grew to 7 GB in a minute): the frame is rendered in seconds.
#[test]
fn a_long_lighting_schedule_of_one_map_opens_it_once() {
    let (dir, _, model) = trained_model("schedule", &[]);
    let segment = r#"{"map": "builtin:sky", "weight": 1, "rotation_deg": [0, 10]}"#;
    let segments = vec![segment; 10_000].join(",");
    let schedule = dir.join("schedule.json");
    std::fs::write(&schedule, format!(r#"{{"segments": [{segments}]}}"#)).unwrap();
    let started = std::time::Instant::now();
    let out = render_exr(
        model.to_str().unwrap(),
        &dir.join("frames"),
        "2",
        &["--lighting", schedule.to_str().unwrap()],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let seconds = started.elapsed().as_secs_f64();
    assert!(seconds < 30.0, "two frames took {seconds:.0} s");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A checkpoint whose state says more epochs than steps (edited to 10⁹, which replayed a
/// billion epochs' shuffles before the first step) is refused at once as damaged.
#[test]
fn a_damaged_resume_state_is_refused_at_once() {
    let (dir, data, model) = trained_model("state", &["--schedule", "paper"]);
    let (d, m) = (data.to_str().unwrap(), model.to_str().unwrap());
    let state = model.join("checkpoint/state.json");
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&state).unwrap()).unwrap();
    json["epoch"] = serde_json::json!(1_000_000_000u64);
    std::fs::write(&state, json.to_string()).unwrap();
    fails_in_time(
        &train_args(d, m, &["--epochs", "2", "--schedule", "paper"]),
        &["state.json", "is damaged", "1000000000 epochs"],
    );
    // Forged consistently (as many steps and samples as epochs), the state is a finished run:
    // its batches are read, not replayed, and the run ends at once.
    for key in ["step", "samples"] {
        json[key] = serde_json::json!(1_000_000_000u64);
    }
    std::fs::write(&state, json.to_string()).unwrap();
    let started = std::time::Instant::now();
    ok(&train_args(d, m, &["--epochs", "2", "--schedule", "paper"]));
    let seconds = started.elapsed().as_secs_f64();
    assert!(seconds < 30.0, "the forged state took {seconds:.0} s");
    // The run's own length is bounded where a plan of every epoch is made.
    let out = nprt(&train_args(d, m, &["--epochs", "1000000000"]));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("'1000000000' for '--epochs") && err.contains("1..=100000"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A manifest naming one view file twice under two spellings (`views/./NAME`), which trained
/// on that view twice, and a model whose bounds are inverted (which changed the rendered image
/// silently), are refused by name.
#[test]
fn two_spellings_of_a_file_and_inverted_bounds_are_refused() {
    let (dir, data, model) = trained_model("spellings", &[]);
    let (d, m) = (data.to_str().unwrap(), model.to_str().unwrap());
    let json = std::fs::read_to_string(model.join("model.json")).unwrap();
    let mut file: serde_json::Value = serde_json::from_str(&json).unwrap();
    let bounds = file["bounds"].clone();
    file["bounds"] = serde_json::json!([bounds[1], bounds[0]]);
    std::fs::write(model.join("model.json"), file.to_string()).unwrap();
    fails(
        &["model", "info", "--model", m],
        &["model '", "bounds", "not a finite box"],
    );
    let manifest = data.join("manifest.json");
    let text = std::fs::read_to_string(&manifest).unwrap();
    let mut m: serde_json::Value = serde_json::from_str(&text).unwrap();
    let first = m["views"][0]["file"]
        .as_str()
        .unwrap()
        .replacen('/', "/./", 1);
    m["views"][1]["file"] = serde_json::json!(first);
    std::fs::write(&manifest, m.to_string()).unwrap();
    fails(
        &["dataset", "verify", d],
        &["views/./", "named by more than one view"],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The smaller cases: camera flags on a scene's own volume, `reference --spp 0`,
/// `train --val-samples 0`, and error messages that say the OS's reason once.
#[test]
fn small_cases_are_answered_precisely() {
    let dir = fresh_dir("small");
    let data = dir.join("ds");
    let mut args = vec![
        "generate",
        "--scene",
        "builtin:room",
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
        "1",
        "--test-spp",
        "2",
    ];
    args.extend(["--fov", "45", "--spread", "10"]);
    ok(&args);
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(data.join("manifest.json")).unwrap()).unwrap();
    let volume = &json["settings"]["camera_volume"];
    assert_eq!(
        (volume["fov_deg"].as_f64(), volume["spread_deg"].as_f64()),
        (Some(45.0), Some(10.0))
    );
    assert!(json["views"]
        .as_array()
        .unwrap()
        .iter()
        .all(|v| v["fov_x_deg"] == 45.0));

    // No validation samples: refused, not silently one.
    let model = dir.join("model");
    fails(
        &train_args(
            data.to_str().unwrap(),
            model.to_str().unwrap(),
            &["--epochs", "1", "--val-samples", "0"],
        ),
        &["validation samples must be positive"],
    );
    assert!(!model.join("model.json").exists());

    let x = dir.join("x.exr");
    let mut zero = reference_args(&x);
    zero[5] = "0";
    fails(&zero, &["samples per pixel must be at least 1"]);

    let o = nprt(&[
        "reference",
        "builtin:room",
        "--envmap",
        "/nonexistent/map.exr",
        "--out",
        dir.join("y.exr").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(err.matches("(os error 2)").count(), 1, "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Geometry collapsed onto a point (a shape scaled by 0 or 10⁻³⁰: a stack overflow in the BVH
/// builder, found by the `scene_geometry` fuzz target) and many coincident copies of one shape
/// (300 spheres ran past two minutes) are traced: what a ray cannot hit, or hits at the same
/// distance as an earlier copy, is left out of the BVH.
#[test]
fn collapsed_and_coincident_geometry_is_traced() {
    let dir = fresh_dir("collapsed");
    std::fs::create_dir_all(&dir).unwrap();
    let collapsed = r#"<shape type="sphere"><transform name="to_world"><scale value="0"/></transform></shape>
        <shape type="cube"><transform name="to_world"><scale value="1e-30"/></transform></shape>
        <shape type="rectangle"/>"#;
    let copies = r#"<shape type="sphere"/>"#.repeat(60);
    for (name, shapes) in [("collapsed", collapsed), ("copies", copies.as_str())] {
        let scene = dir.join(format!("{name}.xml"));
        std::fs::write(
            &scene,
            format!(r#"<scene version="3.0.0">{shapes}</scene>"#),
        )
        .unwrap();
        let out = dir.join(name);
        let mut args = reference_args(&out);
        args[1] = scene.to_str().unwrap();
        let (code, text) = run_in_time(&args);
        assert_eq!(code, Some(0), "{name}: {text}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Starts a long CPU training on a tiny dataset, waits for its first checkpoint (the pack is
/// open and read by then), lets `damage` change the pack under it, and returns the run's exit
/// status and output.
fn train_while(name: &str, damage: impl FnOnce(&Path)) -> (Option<i32>, String, PathBuf) {
    let (dir, data) = with_dataset(name);
    let model = dir.join("model");
    let (d, m) = (data.to_str().unwrap(), model.to_str().unwrap());
    let args = train_args(
        d,
        m,
        &[
            "--epochs",
            "20000",
            "--checkpoint-minutes",
            "0",
            "--device",
            "cpu",
        ],
    );
    let child = Command::new(env!("CARGO_BIN_EXE_nprt"))
        .args(&args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while !model.join("checkpoint/state.json").exists() {
        assert!(
            started.elapsed().as_secs() < 60,
            "no checkpoint after a minute"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    damage(&data.join("packed-radiance.bin"));
    let out = child.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&out.stderr) + String::from_utf8_lossy(&out.stdout);
    (out.status.code(), text.into_owned(), dir)
}

/// A pack cut short while a training maps it ends the run with a message naming the pack
/// (it died of a bare SIGBUS, status 135); random bytes written over its records end it at
/// the latest before the last save, named as a changed dataset (not blamed on --lr), and no
/// model is left behind either way.
#[test]
fn a_pack_changed_during_training_is_named() {
    let (code, text, dir) = train_while("bus", |pack| {
        std::fs::OpenOptions::new()
            .write(true)
            .open(pack)
            .unwrap()
            .set_len(0)
            .unwrap();
    });
    assert_eq!(code, Some(1), "{text}");
    assert!(
        text.contains("packed-radiance.bin' changed while this process had it mapped"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
    let (code, text, dir) = train_while("scribbled", |pack| {
        use std::io::{Seek, SeekFrom, Write};
        let mut f = std::fs::OpenOptions::new().write(true).open(pack).unwrap();
        let len = f.metadata().unwrap().len();
        f.seek(SeekFrom::Start(len - 4096)).unwrap();
        let noise: Vec<u8> = (0..4096u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
            .collect();
        f.write_all(&noise).unwrap();
    });
    assert_eq!(code, Some(1), "{text}");
    assert!(
        text.contains("the dataset changed while the run read it")
            && text.contains("packed-radiance.bin' are damaged")
            && !text.contains("lower --lr"),
        "{text}"
    );
    assert!(!dir.join("model/weights.safetensors").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Another design's optimiser state put in a checkpoint (a baseline run's moments in a D/S
/// folder, which panicked in burn) is refused by name when the run resumes.
#[test]
fn another_designs_optimiser_state_is_refused_on_resume() {
    let (dir, data, baseline) = trained_model("adam-swap", &["--schedule", "paper"]);
    let d = data.to_str().unwrap();
    let dsep = dir.join("dsep");
    let m = dsep.to_str().unwrap();
    let args = |epochs| {
        let mut a = train_args(d, m, &["--epochs", epochs, "--schedule", "paper"]);
        a[4] = "dsep";
        a
    };
    ok(&args("1"));
    let state = |model: &Path| -> String {
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(model.join("checkpoint/state.json")).unwrap())
                .unwrap();
        json["optimizer"].as_str().unwrap().to_string()
    };
    let theirs = baseline.join("checkpoint").join(state(&baseline));
    let ours = dsep.join("checkpoint").join(state(&dsep));
    std::fs::copy(&theirs, &ours).unwrap();
    fails_in_time(
        &args("2"),
        &["Adam's state", &state(&dsep), "not this network's"],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
