//! The `nprt` binary as a user meets it: successful renders, and bad input that must stop with
//! an error naming the file and the reason, leaving no output behind.

mod common;

use common::{assets, fails, fresh_dir, nprt};
use nprt_io::exr::{read_channels, write_channels};

/// A created scratch folder.
fn tmp(name: &str) -> std::path::PathBuf {
    let d = fresh_dir(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn reference_renders_a_gltf_and_reports_speed() {
    let out_dir = tmp("ok");
    let exr = out_dir.join("bunny.exr");
    let png = out_dir.join("bunny.png");
    let bunny = assets().join("models/bunny_plain.glb");
    let o = nprt(&[
        "reference",
        bunny.to_str().unwrap(),
        "--out",
        exr.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
        "--envmap",
        "builtin:sky:30:200:3",
        "--width",
        "48",
        "--height",
        "48",
        "--spp",
        "4",
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("alpha mode Blend is traced as opaque"),
        "{stderr}"
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        stdout.contains("Msamples/s") && stdout.contains("48×48 at 4 spp"),
        "{stdout}"
    );
    let (w, h, ch) = read_channels(&exr).unwrap();
    assert_eq!((w, h), (48, 48));
    let covered: f32 = ch["mask"].iter().sum();
    assert!(
        covered > 200.0 && covered < 2000.0,
        "the framed bunny covers part of the image: {covered}"
    );
    for name in [
        "R",
        "direct.G",
        "position.X",
        "normal.Z",
        "view.Y",
        "kd.R",
        "ks.B",
        "alpha",
    ] {
        assert!(ch.contains_key(name), "missing channel {name}");
    }
    assert!(png.exists());
}

#[test]
fn draco_gltf_is_refused_by_name() {
    let out = tmp("draco").join("x.exr");
    let bunny = assets().join("models/bunny.glb");
    fails(
        &[
            "reference",
            bunny.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--envmap",
            "builtin:sky",
        ],
        &["bunny.glb", "KHR_draco_mesh_compression"],
    );
    assert!(!out.exists());
}

/// `nprt reference builtin:room --envmap MAP` must fail naming `needles`.
fn map_refused(out: &std::path::Path, map: &str, needles: &[&str]) {
    let args = [
        "reference",
        "builtin:room",
        "--out",
        out.to_str().unwrap(),
        "--envmap",
        map,
    ];
    fails(&args, needles);
}

#[test]
fn bad_environment_maps_are_refused_by_name() {
    let dir = tmp("maps");
    let out = dir.join("x.exr");
    // Not 2:1.
    let odd = dir.join("odd.hdr");
    image::Rgb32FImage::from_pixel(30, 16, image::Rgb([1.0, 1.0, 1.0]))
        .save(&odd)
        .unwrap();
    map_refused(&out, odd.to_str().unwrap(), &["odd.hdr", "2:1", "30×16"]);
    // A compression the reader lacks: a valid file whose header claims HTJ2K.
    let htj2k = dir.join("htj2k.exr");
    let data = vec![0.5f32; 16 * 8];
    write_channels(
        &htj2k,
        16,
        8,
        &[
            ("R".into(), data.clone()),
            ("G".into(), data.clone()),
            ("B".into(), data),
        ],
    )
    .unwrap();
    let mut bytes = std::fs::read(&htj2k).unwrap();
    let key = b"compression\0compression\0\x01\0\0\0";
    let at = bytes
        .windows(key.len())
        .position(|w| w == key)
        .expect("compression attribute")
        + key.len();
    bytes[at] = 10;
    std::fs::write(&htj2k, bytes).unwrap();
    map_refused(&out, htj2k.to_str().unwrap(), &["htj2k.exr", "compression"]);
    // Missing file and unknown built-in.
    map_refused(&out, "/nonexistent/map.exr", &["/nonexistent/map.exr"]);
    map_refused(&out, "builtin:moon", &["builtin:moon"]);
    assert!(!out.exists());
}

#[test]
fn bad_scenes_arguments_and_outputs_are_refused() {
    let dir = tmp("scenes");
    let out = dir.join("x.exr");
    let o = out.to_str().unwrap();
    fails(
        &["reference", "/nonexistent/scene.xml", "--out", o],
        &["/nonexistent/scene.xml", "does not exist"],
    );
    fails(
        &["reference", "builtin:attic", "--out", o],
        &["builtin:attic", "builtin:room"],
    );
    let txt = dir.join("scene.txt");
    std::fs::write(&txt, "hello").unwrap();
    fails(
        &["reference", txt.to_str().unwrap(), "--out", o],
        &["scene.txt", "unknown format"],
    );
    let xml = dir.join("plugin.xml");
    std::fs::write(
        &xml,
        "<scene version=\"3.0.0\">\n  <shape type=\"hair\"/>\n</scene>\n",
    )
    .unwrap();
    fails(
        &["reference", xml.to_str().unwrap(), "--out", o],
        &["plugin.xml:2:", "hair"],
    );
    fails(
        &["reference", "builtin:room", "--out", o, "--set", "novalue"],
        &["NAME=VALUE", "novalue"],
    );
    let data = dir.join("data");
    for (train, test) in [("0", "1"), ("1", "0")] {
        fails(
            &[
                "generate",
                "--scene",
                "builtin:room",
                "--envmaps",
                "builtin",
                "--out",
                data.to_str().unwrap(),
                "--train-views",
                train,
                "--test-views",
                test,
            ],
            &["at least one training and one test view"],
        );
    }
    assert!(!data.exists());
    fails(
        &[
            "reference",
            "builtin:room",
            "--out",
            "/proc/nprt-cannot-write/x.exr",
            "--spp",
            "1",
        ],
        &["/proc/nprt-cannot-write"],
    );
    assert!(!out.exists());
}

/// `--envmap` replaces the scene's lighting, so the scene's own map file is never opened: a
/// scene whose map is absent renders with it, and without it fails naming the missing file.
#[test]
fn envmap_replaces_a_scene_map_that_is_missing() {
    let dir = tmp("missing-map");
    std::fs::create_dir_all(&dir).unwrap();
    let xml = dir.join("lit.xml");
    std::fs::write(
        &xml,
        "<scene version=\"3.0.0\">\n  <shape type=\"rectangle\"/>\n  \
         <emitter type=\"envmap\"><string name=\"filename\" value=\"gone.exr\"/></emitter>\n</scene>\n",
    )
    .unwrap();
    let out = dir.join("x.exr");
    let args = |extra: &[&'static str]| -> Vec<String> {
        let mut a: Vec<String> = [
            "reference",
            xml.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]
        .map(String::from)
        .into();
        a.extend(["--spp", "1", "--width", "8", "--height", "8"].map(String::from));
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    fn run(a: &[String]) -> Vec<&str> {
        a.iter().map(String::as_str).collect()
    }
    fails(&run(&args(&[])), &["gone.exr"]);
    assert!(!out.exists());
    let text = common::ok(&run(&args(&["--envmap", "builtin:sky"])));
    assert!(text.contains("rendered 8×8"), "{text}");
    assert!(out.exists());
}

#[test]
fn help_explains_every_flag() {
    let o = nprt(&["reference", "--help"]);
    let text = String::from_utf8_lossy(&o.stdout);
    for flag in [
        "--out",
        "--spp",
        "--set",
        "--envmap",
        "--rotate",
        "--max-depth",
        "--width",
        "--height",
        "--seed",
        "--png",
        "--centre",
        "--threads",
    ] {
        assert!(text.contains(flag), "reference --help lacks {flag}");
    }
}

/// `--device gpu` takes a hardware adapter only: where there is none (CI's lavapipe is a
/// software one) it says so and names `wgpu`, and `auto` runs on the CPU saying why.
#[test]
fn device_gpu_without_one_fails_clearly_and_auto_falls_back() {
    let run = common::tiny_frame;
    let gpu = run("gpu");
    if gpu.status.success() {
        // A machine with a GPU: the frame ran on its kernels.
        assert!(String::from_utf8_lossy(&gpu.stdout).contains("networks on the GPU kernels on"));
    } else {
        let err = String::from_utf8_lossy(&gpu.stderr);
        let clear = if cfg!(feature = "gpu") {
            err.contains("--device gpu: the only GPU adapter is a software one")
                && err.contains("--device wgpu")
                || err.contains("no GPU adapter found")
        } else {
            err.contains("--device gpu: this nprt was built without its GPU kernels")
        };
        assert!(clear, "{err}");
        let auto = run("auto");
        assert!(auto.status.success());
        assert!(String::from_utf8_lossy(&auto.stdout).contains("networks on the CPU engine"));
        if cfg!(feature = "gpu") {
            let err = String::from_utf8_lossy(&auto.stderr);
            assert!(err.contains("--device auto: running on the CPU: "), "{err}");
        }
    }
    let bad = run("tpu");
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("expected cpu, gpu, wgpu or auto"));
}

/// A stand-in for the PyTorch peer: a script that reports the samples/s listed in `rates`,
/// one per call in turn (its calls counted in `calls`), or fails with `boom` when `rates` is
/// empty.
fn fake_peer(dir: &std::path::Path, rates: &[u32]) -> std::path::PathBuf {
    let script = dir.join("python");
    let calls = dir.join("calls");
    let body = if rates.is_empty() {
        "echo boom >&2; exit 1".to_string()
    } else {
        format!(
            "echo x >> '{calls}'; n=$(wc -l < '{calls}'); rates=({rates})\n\
             echo \"{{\\\"design\\\": \\\"baseline\\\", \\\"samples_per_s\\\": ${{rates[$((n - 1))]}}}}\"",
            calls = calls.display(),
            rates = rates.iter().map(u32::to_string).collect::<Vec<_>>().join(" ")
        )
    };
    // The script nprt hands its peer must be the embedded PyTorch benchmark.
    let check =
        "grep -q 'samples_per_s' \"$1\" || { echo \"not the peer script: $1\" >&2; exit 1; }";
    std::fs::write(&script, format!("#!/usr/bin/env bash\n{check}\n{body}\n")).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&script, std::fs::Permissions::from_mode(0o755)).unwrap();
    script
}

/// The cells of `bench train`'s baseline row.
fn baseline_row(out: &str) -> Vec<&str> {
    out.lines()
        .find(|l| l.starts_with("baseline"))
        .unwrap_or_else(|| panic!("no baseline row in:\n{out}"))
        .split_whitespace()
        .collect()
}

#[test]
fn bench_train_alternates_rounds_with_the_peer_and_compares_medians() {
    let dir = tmp("bench-peer");
    let args = |python: &std::path::Path| {
        let mut a: Vec<String> = "bench train --arch baseline --batch-size 64 --views 1 \
                                  --steps 1 --warmup 0 --rounds 3 --device cpu --python"
            .split(' ')
            .map(String::from)
            .collect();
        a.push(python.display().to_string());
        a
    };
    let python = fake_peer(&dir, &[1000, 5000, 2000]);
    let a = args(&python);
    let out = common::ok(&a.iter().map(String::as_str).collect::<Vec<_>>());
    // One peer run per round, and the median of its three rates (not their mean, 2667) in
    // the PyTorch column.
    let calls = std::fs::read_to_string(dir.join("calls")).unwrap();
    assert_eq!(calls.lines().count(), 3, "{out}");
    let row = baseline_row(&out);
    assert_eq!(row[2], "f32", "{out}");
    assert_eq!(row[4], "2000", "{out}");
    let ours: f64 = row[3].parse().unwrap();
    let ratio: f64 = row[5].trim_end_matches('×').parse().unwrap();
    assert!((ratio - ours / 2000.0).abs() <= 0.01, "{out}");
    assert!(
        row[6].contains('–'),
        "no range of the rounds' ratios: {out}"
    );

    let failing = fake_peer(&tmp("bench-peer-fails"), &[]);
    let a = args(&failing);
    common::fails(
        &a.iter().map(String::as_str).collect::<Vec<_>>(),
        &["PyTorch peer failed: boom"],
    );
}

/// Several PyTorch variants: each runs every round with its own flags, and the fastest by its
/// median is the peer, named in the last column.
#[test]
fn bench_train_compares_with_the_fastest_peer_variant() {
    let dir = tmp("bench-variants");
    let script = dir.join("python");
    // compile-bf16 runs at 3000 samples/s, eager-f32 at 1000; the flags are logged.
    std::fs::write(
        &script,
        format!(
            "#!/usr/bin/env bash\necho \"$*\" >> '{}'\n\
             case \"$*\" in *--compile*--autocast\\ bf16*) r=3000;; *) r=1000;; esac\n\
             echo \"{{\\\"samples_per_s\\\": $r}}\"\n",
            dir.join("calls").display()
        ),
    )
    .unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&script, std::fs::Permissions::from_mode(0o755)).unwrap();
    let out = common::ok(&[
        "bench",
        "train",
        "--arch",
        "baseline",
        "--batch-size",
        "64",
        "--views",
        "1",
        "--steps",
        "1",
        "--warmup",
        "0",
        "--rounds",
        "2",
        "--device",
        "cpu",
        "--python",
        script.to_str().unwrap(),
        "--peer-variants",
        "eager-f32,compile-bf16",
    ]);
    let calls = std::fs::read_to_string(dir.join("calls")).unwrap();
    assert_eq!(calls.lines().count(), 4, "{calls}");
    assert_eq!(
        calls.lines().filter(|l| l.contains("--compile")).count(),
        2,
        "{calls}"
    );
    let row = baseline_row(&out);
    assert_eq!(row[4], "3000", "{out}");
    assert_eq!(row[7], "compile-bf16", "{out}");
}

/// `bench infer` times every design, a row each: the linear designs' light codes are their
/// basis' projections (3K values), not the encoder's code (it panicked on them once).
#[test]
fn bench_infer_times_every_design() {
    let designs = nprt_net::Design::ALL.map(|d| d.name());
    let arch = designs.join(",");
    let out = common::ok(&[
        "bench",
        "infer",
        "--arch",
        &arch,
        "--resolution",
        "8",
        "--repeats",
        "1",
    ]);
    let rows: Vec<&str> = (out.lines())
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    for name in designs {
        assert!(rows.contains(&name), "no row of {name}: {out}");
    }
}

#[test]
fn bench_frame_times_every_stage_on_each_device() {
    let mut devices = vec!["cpu"];
    if common::wgpu_runs() {
        devices.push("wgpu");
    }
    for device in devices {
        let args = "bench frame --arch prt --res 48x32,32 --repeats 1 --direct-spp 16 --device";
        let mut args: Vec<&str> = args.split(' ').collect();
        args.push(device);
        let out = common::ok(&args);
        let rows: Vec<(&str, Vec<f64>)> = out
            .lines()
            .filter(|l| l.starts_with("prt") || l.starts_with("dsep+direct"))
            .map(|l| {
                (
                    l,
                    l.split_whitespace()
                        .skip(2)
                        .map(|c| c.parse().unwrap())
                        .collect(),
                )
            })
            .collect();
        assert_eq!(rows.len(), 4, "{out}");
        for (row, cols) in &rows {
            let [pixels, gbuffer, encoder, networks, direct, total, _fps, relight] = cols[..]
            else {
                panic!("{row}")
            };
            assert!(
                pixels > 0.0 && gbuffer > 0.0 && encoder > 0.0 && networks > 0.0 && relight > 0.0,
                "{row}"
            );
            // Traced light is timed in its own column (how it compares with the background
            // fill is a benchmark's question: on a loaded CI machine it came out 2.7x, not 3x).
            assert!(!row.starts_with("dsep+direct") || direct > 0.0, "{row}");
            // Each column is printed rounded to 0.1 ms: the four parts and the total may
            // disagree by up to 5 × 0.05 (seen: 389.9 against 389.7).
            assert!(
                (total - (gbuffer + encoder + networks + direct)).abs() < 0.26,
                "{row}"
            );
        }
        let (networks, gbuffer) = if device == "cpu" {
            ("networks on the CPU engine", "G-buffer traced on the CPU")
        } else {
            (
                "networks on the GPU kernels on",
                "G-buffer rasterised on the GPU",
            )
        };
        assert!(out.contains(networks) && out.contains(gbuffer), "{out}");
        // On the GPU a lighting change of a model whose networks give all the light waits for
        // the queue once, to read the frame back; traced light is waited for apart (timed).
        let once = "the host waited for the GPU 1 time(s) in a lighting change";
        let expected = if device == "cpu" { 0 } else { 2 };
        assert_eq!(out.matches(once).count(), expected, "{out}");
        let shown = "left on the device, as nprt view shows it";
        assert_eq!(out.matches(shown).count(), 2 * expected, "{out}");
    }
}

/// `nprt bench frame --precision f32,f16 --profile` on the GPU kernels: a row per precision,
/// the f16 ones saying where they ran, and each row followed by its lighting change's kernels
/// (lavapipe's timestamps are not a GPU's, so only their presence is checked). Both flags are
/// refused where the networks run on the CPU.
#[test]
fn bench_frame_times_half_precision_and_profiles_kernels_on_the_gpu() {
    let on_cpu = "bench frame --arch prt --res 32 --direct-spp 0 --device cpu";
    let profile = format!("{on_cpu} --profile");
    let profile: Vec<&str> = profile.split(' ').collect();
    common::fails(&profile, &["--profile", "--device wgpu"]);
    let half = format!("{on_cpu} --precision f16");
    let half: Vec<&str> = half.split(' ').collect();
    common::fails(&half, &["--precision f16", "--device wgpu"]);
    if !common::wgpu_runs() {
        return;
    }
    let both = "bench frame --arch dsep --res 32 --repeats 1 --direct-spp 0 --device wgpu \
                --precision f32,f16 --profile";
    let out = common::ok(&both.split(' ').collect::<Vec<_>>());
    let rows: Vec<&str> = out.lines().filter(|l| l.starts_with("dsep")).collect();
    assert_eq!(rows.len(), 2, "{out}");
    assert!(rows[1].starts_with("dsep f16 "), "{out}");
    assert!(out.contains("(f16"), "{out}");
    assert_eq!(
        out.matches("a lighting change's kernels:").count(),
        2,
        "{out}"
    );
    // f16 runs each MLP in one dispatch (the fused pass), f32 a layer a dispatch.
    assert!(out.contains("half_mlp") && out.contains("gemm"), "{out}");
}

/// bench/gpu.sh explains itself, refuses bad arguments, and on a machine without an NVIDIA GPU
/// (CI's) says so before it builds or measures anything.
#[test]
fn the_gpu_benchmark_script_explains_itself_and_names_what_it_lacks() {
    let run = |args: &[&str]| common::script("bench/gpu.sh", args);
    let help = run(&["--help"]);
    assert!(help.status.success());
    let text = String::from_utf8_lossy(&help.stdout);
    assert!(
        text.contains("--kitchen") && text.contains("one summary file"),
        "{text}"
    );
    for (args, code, why) in [
        (&["--frobnicate"][..], 2, "unknown argument '--frobnicate'"),
        (&["--kitchen", "data"][..], 2, "--kitchen needs --cpu-model"),
        (
            &["--quick", "--prepared", "/nonexistent"][..],
            1,
            "--quick needs bench/gpu-prepare.sh's folder '/nonexistent'",
        ),
    ] {
        let out = run(args);
        assert_eq!(out.status.code(), Some(code), "{args:?}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains(why),
            "{args:?}"
        );
    }
    let has_nvidia = std::process::Command::new("sh")
        .args(["-c", "command -v nvidia-smi"])
        .output()
        .unwrap()
        .status
        .success();
    if !has_nvidia {
        let out = run(&["--summary", "/nonexistent/summary.md"]);
        assert_eq!(out.status.code(), Some(1));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("no nvidia-smi: this needs an NVIDIA GPU"),
            "{err}"
        );
    }
}

/// bench/gpu-ab.sh explains itself and names what is wrong with its arguments; where the GPU
/// kernels run (lavapipe here), it times two builds (here one binary twice) alternately and
/// prints a row of the A/B table per design, precision and batch size.
#[test]
fn the_ab_script_times_two_builds_side_by_side() {
    let run = |args: &[&str]| common::script("bench/gpu-ab.sh", args);
    let help = run(&["--help"]);
    assert!(help.status.success());
    let text = String::from_utf8_lossy(&help.stdout);
    assert!(
        text.contains("build REV FILE") && text.contains("alternately"),
        "{text}"
    );
    let nprt = env!("CARGO_BIN_EXE_nprt");
    for (args, why) in [
        (
            &["run", nprt, nprt, "--frobnicate"][..],
            "unknown argument '--frobnicate'",
        ),
        (
            &["run", "/nonexistent", nprt][..],
            "A, '/nonexistent', is not an executable nprt",
        ),
        (
            &["run", nprt, nprt, "--rounds", "0"][..],
            "--rounds must be a positive count",
        ),
        (
            &["build", "no-such-commit", "/nonexistent/nprt"][..],
            "'no-such-commit' names no commit",
        ),
    ] {
        let out = run(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(why), "{args:?}: {err}");
    }
    if !common::wgpu_runs() {
        return;
    }
    // The linear design: no light encoder, whose convolutions are most of a step on lavapipe
    // (prt's rows took 41 s of this test).
    let args = "--device wgpu --arch linear --precision f32 --batch-size 64 --steps 1 --rounds 1 \
                --frames 32";
    let out = run(&[
        &["run", nprt, nprt][..],
        &args.split(' ').collect::<Vec<_>>(),
    ]
    .concat());
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{table}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let row = table
        .lines()
        .find(|l| l.starts_with("| linear | f32 | 64 |"));
    let cells: Vec<&str> = row
        .expect("a row for linear")
        .split('|')
        .map(str::trim)
        .collect();
    // Design, precision, batch, A's and B's samples/s, B/A and the rounds' range.
    let rate = |c: &str| c.parse::<f64>().unwrap_or_else(|_| panic!("{table}"));
    assert!(rate(cells[4]) > 0.0 && rate(cells[5]) > 0.0, "{table}");
    assert!(
        cells[6].ends_with('×') && cells[7].ends_with('×'),
        "{table}"
    );
    // And a 32² frame's new viewpoint, in ms.
    let row = table
        .lines()
        .find(|l| l.starts_with("| linear | f32 | 32 |"));
    let cells: Vec<&str> = row
        .expect("a frame row")
        .split('|')
        .map(str::trim)
        .collect();
    assert!(rate(cells[4]) > 0.0 && rate(cells[5]) > 0.0, "{table}");
    assert!(cells[6].ends_with('×'), "{table}");
}
