//! `nprt view` opens its window on an X display (a private Xvfb when there is none; scripts/
//! xvfb.sh installs it), draws through wgpu on Mesa's software Vulkan, and writes what it
//! shows: the overlay over the frame, and without it the frame `nprt render` makes of the same
//! camera and lighting. Without Xvfb and a display the test skips, unless NPRT_REQUIRE_XVFB is
//! set (scripts/test sets it).
#![cfg(feature = "gpu")]

mod common;

use std::path::Path;
use std::process::{Child, Command, Stdio};

use common::{fresh_dir, ok, tiny_room_model, wgpu_runs};

/// An X display for the viewer: the environment's, or a private Xvfb (killed on drop).
struct Display {
    name: String,
    server: Option<Child>,
}

impl Drop for Display {
    fn drop(&mut self) {
        if let Some(server) = &mut self.server {
            server.kill().ok();
            server.wait().ok();
        }
    }
}

fn display() -> Option<Display> {
    if let Ok(name) = std::env::var("DISPLAY") {
        return Some(Display { name, server: None });
    }
    // A display number of this test's own: parallel runs, and this binary's tests run on
    // threads at once, must not collide (one's Xvfb killed under the other).
    static NEXT: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let test = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed) % 4;
    let name = format!(":{}", 100 + (std::process::id() % 800) * 4 + test);
    match Command::new("Xvfb")
        .args([&name, "-screen", "0", "640x480x24", "-nolisten", "tcp"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
    {
        Ok(server) => {
            let socket = format!("/tmp/.X11-unix/X{}", &name[1..]);
            for _ in 0..100 {
                if Path::new(&socket).exists() {
                    break;
                }
                std::thread::sleep(std::time::Duration::from_millis(50));
            }
            Some(Display {
                name,
                server: Some(server),
            })
        }
        Err(e) => {
            assert!(
                std::env::var_os("NPRT_REQUIRE_XVFB").is_none(),
                "NPRT_REQUIRE_XVFB is set but Xvfb does not start: {e}"
            );
            eprintln!("skipped: no display and no Xvfb ({e}); scripts/xvfb.sh installs it");
            None
        }
    }
}

/// Runs `nprt view` on `display`, expecting success; returns what it printed.
fn view(display: &Display, args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_nprt"))
        .arg("view")
        .args(args)
        .env("DISPLAY", &display.name)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "nprt view {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The recommended recipe's model (`nprt train` without `--arch`): the viewer says what runs,
/// its direct light traced and, where OIDN is installed, denoised by default (`--denoise-direct
/// off`, or the O key, leaves it raw): the denoised frame is the smoother.
#[test]
fn a_recipe_model_is_shown_with_its_traced_light_denoised_and_says_what_runs() {
    let Some(display) = display() else { return };
    let dir = fresh_dir("view-recipe");
    let model = tiny_room_model(&dir, &[]);
    let m = model.to_str().unwrap();
    let oidn = nprt_render::oidn::Oidn::open().is_ok();
    assert!(
        oidn || std::env::var_os("NPRT_REQUIRE_OIDN").is_none(),
        "OIDN is required"
    );
    let shot = |denoise: &str| {
        let shot = dir.join(format!("recipe-{denoise}.png"));
        #[rustfmt::skip]
        let said = view(&display, &[m, "--res", "96x72", "--frames", "2", "--no-overlay",
            "--denoise-direct", denoise, "--screenshot", shot.to_str().unwrap()]);
        (said, image::open(&shot).unwrap().to_rgb8())
    };
    let (said, denoised) = shot("auto");
    let how = if oidn {
        "denoised by OIDN"
    } else {
        "not denoised"
    };
    let line = format!(
        "linear design on sh:2 (siren), direct light traced (4 spp, {how}), level calibrated"
    );
    assert!(said.contains(&line), "no '{line}' in:\n{said}");
    let (said, raw) = shot("off");
    assert!(
        said.contains("direct light traced (4 spp, not denoised)"),
        "{said}"
    );
    if oidn {
        // Differences between horizontal neighbours: the traced light's noise.
        let grain = |img: &image::RgbImage| {
            let mut sum = 0u64;
            for (x, y, p) in img.enumerate_pixels().filter(|(x, _, _)| *x > 0) {
                let q = img.get_pixel(x - 1, y);
                sum += (p.0.iter().zip(q.0))
                    .map(|(a, b)| u64::from(a.abs_diff(b)))
                    .sum::<u64>();
            }
            sum
        };
        let (smooth, noisy) = (grain(&denoised), grain(&raw));
        eprintln!("neighbour differences: denoised {smooth}, raw {noisy}");
        assert!(smooth * 10 < noisy * 8, "denoised {smooth}, raw {noisy}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_viewer_opens_a_window_and_shows_what_render_makes() {
    let Some(display) = display() else { return };
    let dir = fresh_dir("view");
    let model = tiny_room_model(&dir, &["--arch", "prt"]);
    let m = model.to_str().unwrap();

    // With the overlay: text over the frame, in the top-left corner.
    let shot = dir.join("overlay.png");
    view(
        &display,
        &[
            m,
            "--res",
            "160x120",
            "--frames",
            "3",
            "--spin",
            "30",
            "--screenshot",
            shot.to_str().unwrap(),
        ],
    );
    let img = image::open(&shot).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (160, 120));
    let white = |x0: u32, y0: u32, x1: u32, y1: u32| {
        (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0 == [255; 3])
            .count()
    };
    assert!(white(0, 0, 160, 20) > 40, "the overlay's first lines");

    // Without it: the frame nprt render makes from the same camera (the default path's start)
    // and lighting (its first map, unturned), to within rounding of the camera's frame; made on
    // the CPU and uploaded, and where the GPU kernels run, made there and shown from there.
    let bare = |device: &str| {
        let shot = dir.join(format!("bare-{device}.png"));
        view(
            &display,
            &[
                m,
                "--res",
                "160x120",
                "--device",
                device,
                "--frames",
                "1",
                "--no-overlay",
                "--screenshot",
                shot.to_str().unwrap(),
            ],
        );
        image::open(&shot).unwrap().to_rgb8()
    };
    let r = dir.join("render");
    ok(&[
        "render",
        "--model",
        m,
        "--out",
        r.to_str().unwrap(),
        "--frames",
        "1",
        "--res",
        "160x120",
    ]);
    let rendered = image::open(r.join("frames/0000.png")).unwrap().to_rgb8();
    let devices = if wgpu_runs() {
        &["cpu", "wgpu"][..]
    } else {
        &["cpu"]
    };
    for device in devices {
        let shown = bare(device);
        let (mut differ, mut lit) = (0, 0);
        for (a, b) in shown.pixels().zip(rendered.pixels()) {
            differ += usize::from(a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > 2));
            lit += usize::from(a.0.iter().any(|&c| c > 16));
        }
        eprintln!("{device}: {differ} pixels more than 2 levels from nprt render's");
        assert!(
            differ * 100 < 160 * 120,
            "{device}: {differ} pixels differ from nprt render's frame"
        );
        assert!(lit * 2 > 160 * 120, "{device}: the frame shows the room");
    }

    // --camera-volume starts the camera in that volume instead of the scene's sidecar (the
    // KITCHEN's lives in docs/): here, at the back wall looking out of the room's open side, so
    // that the sky fills much of a frame the default view shows none of.
    let volume = dir.join("volume.json");
    std::fs::write(
        &volume,
        r#"{"min": [-0.1, 1.4, -2.6], "max": [0.1, 1.5, -2.5], "look": [0, 0.1, 1],
            "spread_deg": 0, "fov_deg": 60}"#,
    )
    .unwrap();
    let elsewhere = dir.join("elsewhere.png");
    #[rustfmt::skip]
    view(&display, &[m, "--res", "160x120", "--frames", "1", "--no-overlay",
        "--camera-volume", volume.to_str().unwrap(), "--screenshot", elsewhere.to_str().unwrap()]);
    let elsewhere = image::open(&elsewhere).unwrap().to_rgb8();
    let moved = elsewhere
        .pixels()
        .zip(rendered.pixels())
        .filter(|(a, b)| a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > 16))
        .count();
    assert!(
        moved * 4 > 160 * 120,
        "the view did not move: {moved} pixels differ"
    );

    // The progressive reference (the R key) on the GPU, where the kernels run: path traced on
    // the device, it converges to what the CPU's tracer shows.
    if wgpu_runs() {
        let reference = |device: &str| {
            let shot = dir.join(format!("reference-{device}.png"));
            view(
                &display,
                &[
                    m,
                    "--res",
                    "80x60",
                    "--device",
                    device,
                    "--reference",
                    "--frames",
                    "32",
                    "--no-overlay",
                    "--screenshot",
                    shot.to_str().unwrap(),
                ],
            );
            let img = image::open(&shot).unwrap().to_rgb8();
            img.pixels()
                .map(|p| p.0.iter().map(|&c| c as f64).sum::<f64>())
                .sum::<f64>()
                / (80.0 * 60.0 * 3.0)
        };
        let (gpu, cpu) = (reference("wgpu"), reference("cpu"));
        eprintln!("reference's mean 8-bit value: GPU {gpu:.2}, CPU {cpu:.2}");
        assert!(cpu > 16.0 && (gpu / cpu - 1.0).abs() < 0.05);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The number after `what` in `said`'s line that holds it (e.g. "paused at step 12").
fn number_after(said: &str, what: &str) -> f64 {
    let at = said
        .find(what)
        .unwrap_or_else(|| panic!("no '{what}' in:\n{said}"))
        + what.len();
    let digits: String = said[at..]
        .trim_start()
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '.')
        .collect();
    digits
        .parse()
        .unwrap_or_else(|_| panic!("no number after '{what}' in:\n{said}"))
}

/// `nprt view --train`: the window shows the run's newest model as it trains; Space pauses
/// the run (its step counter stops, a save then writes that step), X lengthens it, and closing
/// the window saves it: the model renders, and `nprt train` of the lengthened run resumes it.
/// The later frame is closer to the path-traced reference (R, brought on while the run is
/// paused) than the earlier, and the split view (V) shows the model left of a white divider
/// and the reference right of it.
#[test]
fn the_viewer_trains_a_model_as_it_shows_it_and_saves_it_on_close() {
    let Some(display) = display() else { return };
    let dir = fresh_dir("view-train");
    let data = dir.join("data");
    common::room_dataset(&data, [24, 2], 32, 4);
    let (model, shots) = (dir.join("model"), dir.join("shots"));
    std::fs::create_dir_all(&shots).unwrap();
    let (d, m) = (data.to_str().unwrap(), model.to_str().unwrap());
    // Shots: 0 early, 1 late (after about 24 s of training: fewer, on 2 cores, and the
    // frames are not yet clearly better), 2 the reference, 3 the split view.
    #[rustfmt::skip]
    let keys = "2.5:p,3:space,5:k,6:space,7:x,27:p,27.2:space,27.3:r,33:p,33.2:r,33.3:v,34:p,34.5:escape";
    #[rustfmt::skip]
    let said = view(&display, &["--train", d, "--out", m, "--device", "cpu", "--minutes", "0.5",
        "--extend-minutes", "0.1", "--res", "64x48", "--no-overlay",
        "--screenshot-dir", shots.to_str().unwrap(), "--keys", keys]);
    let paused = number_after(&said, "training paused at step");
    let saved = number_after(&said, "' at step");
    let resumed = number_after(&said, "training resumed at step");
    assert!(
        paused == saved && saved == resumed && paused > 0.0,
        "{said}"
    );
    let trained = number_after(&said, "trained");
    assert!(
        trained > resumed,
        "training went on after the pause:\n{said}"
    );
    let shot = |i: u32| {
        image::open(shots.join(format!("nprt-view-{i:04}.png")))
            .unwrap()
            .to_rgb8()
    };
    let (early, late, reference, split) = (shot(0), shot(1), shot(2), shot(3));
    let l1 = |a: &image::RgbImage| {
        let pairs = a.as_raw().iter().zip(reference.as_raw());
        pairs
            .map(|(&x, &y)| (x as f64 - y as f64).abs())
            .sum::<f64>()
            / a.as_raw().len() as f64
    };
    assert!(
        early.as_raw().iter().any(|&v| v > 0),
        "the early frame shows a model"
    );
    let (l1_early, l1_late) = (l1(&early), l1(&late));
    assert!(
        l1_late < 0.9 * l1_early,
        "L1 {l1_early} then {l1_late}:\n{said}"
    );
    assert!(
        said.contains("nprt-view-0003.png (L1"),
        "the split's L1 said:\n{said}"
    );
    assert!(
        (0..48).all(|y| split.get_pixel(32, y).0 == [255; 3]),
        "no divider"
    );
    assert_ne!(split.get_pixel(10, 24), split.get_pixel(54, 24));

    let frames = dir.join("frames");
    #[rustfmt::skip]
    let rendered = ok(&["render", "--model", m, "--out", frames.to_str().unwrap(),
        "--frames", "1", "--res", "32x24", "--device", "cpu"]);
    assert!(
        rendered.contains("networks on the CPU engine"),
        "{rendered}"
    );
    // X made the run 0.6 minutes long (0.5 + 0.1): `nprt train` of that length continues it.
    let resumed = ok(&[
        "train",
        "--data",
        d,
        "--out",
        m,
        "--minutes",
        "0.6",
        "--device",
        "cpu",
    ]);
    assert!(resumed.contains("resumed from epoch"), "{resumed}");
}

/// `nprt view --train` refuses, before any window opens, what it cannot train: a folder that
/// is no dataset, a model folder that is the dataset itself, a time out of range and a
/// scripted key that is none.
#[test]
fn the_viewer_refuses_a_run_it_cannot_train_before_opening_a_window() {
    let dir = fresh_dir("view-train-refusals");
    let data = dir.join("data");
    common::room_dataset(&data, [2, 1], 8, 1);
    let (d, nothing) = (data.to_str().unwrap(), dir.join("nothing"));
    common::fails(
        &["view", "--train", nothing.to_str().unwrap()],
        &["--train '", "nothing"],
    );
    common::fails(
        &["view", "--train", d, "--out", d],
        &["is a dataset folder"],
    );
    common::fails(&["view", "--train", d, "--minutes", "0"], &["--minutes"]);
    common::fails(
        &["view", "--train", d, "--extend-minutes", "0"],
        &["--extend-minutes"],
    );
    // What the flags' parser refuses is a usage error (exit 2).
    let usage = |args: &[&str], needles: &[&str]| {
        let o = common::nprt(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(needles.iter().all(|n| err.contains(n)), "{args:?}: {err}");
    };
    usage(
        &["view", "--train", d, "--keys", "1:ab"],
        &["'ab'", "is not a key"],
    );
    usage(
        &["view", "--train", d, "--keys", "x:p"],
        &["'x'", "not a time"],
    );
    usage(&["view", "m", "--train", d], &["cannot be used with"]);
}

/// `nprt bake --view` trains the bake's run in the window: closed before the run's minutes,
/// the bake stops with the model saved and says how to continue; the same bake without the
/// window continues the run and checks the model.
#[test]
fn a_bake_trained_in_the_window_stops_when_closed_early_and_continues_without_it() {
    let Some(display) = display() else { return };
    let dir = fresh_dir("bake-view");
    let out = dir.join("run");
    let bake = |window: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_nprt"))
            .args([
                "bake",
                "builtin:room",
                "--envmaps",
                "builtin",
                "--quality",
                "tiny",
            ])
            .args(["--minutes", "0.25", "--device", "cpu"])
            .args(window)
            .arg("--out")
            .arg(&out)
            .env("DISPLAY", &display.name)
            .output()
            .unwrap()
    };
    let early = bake(&["--view", "--keys", "0.1:escape"]);
    let err = String::from_utf8_lossy(&early.stderr);
    assert_eq!(early.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the window closed after") && err.contains("--minutes 0.25"),
        "{err}"
    );
    assert!(out.join("model/model.json").is_file(), "the model is saved");
    let done = bake(&[]);
    let said = String::from_utf8_lossy(&done.stdout);
    let err = String::from_utf8_lossy(&done.stderr);
    assert!(done.status.success(), "{err}");
    assert!(
        (said.clone() + err.clone()).contains("training resumes where a run before stopped"),
        "{said}{err}"
    );
    assert!(said.contains("checked on 2 held-out views"), "{said}");
    assert!(out.join("preview.png").is_file() && out.join("comparison.png").is_file());
}
