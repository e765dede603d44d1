//! `nprt train` on a tiny real dataset: it learns, resumes exactly, refuses what it must.

mod common;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use common::{fails, fresh_dir, ok};

/// 3 training views and 1 test view of builtin:room at 12², 16 spp, made once per process.
fn dataset() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = fresh_dir("train-data");
        common::room_dataset(&dir, [3, 1], 12, 16);
        dir
    })
}

/// Small-run settings: 64-wide encoder input, batches of 64 mixing all 3 views.
fn train(out: &Path, arch: &str, extra: &[&str]) -> String {
    ok(&train_args(out, arch, extra))
}

/// The arguments of [`train`].
fn train_args<'a>(out: &'a Path, arch: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "train",
        "--data",
        dataset().to_str().unwrap(),
        "--arch",
        arch,
        "--out",
        out.to_str().unwrap(),
        "--encoder-width",
        "64",
        "--batch-size",
        "64",
        "--views-per-batch",
        "3",
        "--val-samples",
        "256",
    ];
    args.extend_from_slice(extra);
    args
}

/// (train, val) columns of loss.csv, empty cells as None.
fn losses(model: &Path) -> Vec<(Option<f64>, Option<f64>)> {
    let csv = std::fs::read_to_string(model.join("loss.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("step,epoch,samples,seconds,train_loss,val_loss")
    );
    lines
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (c[4].parse().ok(), c[5].parse().ok())
        })
        .collect()
}

/// 150 epochs: the three losses fall to 1/71, 1/27 and 1/52 of their start (an eighth is
/// asked); 300 took twice the time for margins of no use.
#[test]
fn a_tiny_dataset_is_overfit() {
    overfits(
        &[("prt", "none"), ("dsep", "none"), ("dsep", "hash-grid")],
        "cpu",
        150,
    );
}

/// The GPU training steps (nprt-net's own kernels, parameters and Adam's moments kept on the
/// device) on wgpu, which CI runs on a software Vulkan device: it learns.
#[test]
fn the_gpu_path_overfits() {
    if !common::wgpu_runs() {
        return;
    }
    // Fewer epochs than the CPU's: the software device is about twenty times slower than the
    // CPU engine (its light encoder's convolutions take three quarters of a step). After 80
    // the loss has fallen to a fourteenth (0.048 to 0.0035; after 100 to a twenty-second, after
    // 60 not quite to an eighth, which the test asks).
    overfits(&[("dsep", "hash-grid")], "wgpu", 80);
}

/// The GPU training steps resume exactly (the hash grid's gradient is summed in a fixed order
/// for that), and a run started on them continues on the CPU engine.
#[test]
fn the_gpu_path_resumes_exactly() {
    if !common::wgpu_runs() {
        return;
    }
    resumes_exactly("wgpu");
    resumes_across_engines();
}

/// `train-deep-shading --device wgpu`: the U-Net on the kernels takes the CPU engine's path
/// (same initial weights, batches and f32 arithmetic up to the order of sums: every epoch's
/// validation loss within 1e-3 of the CPU's; lavapipe: 2.4e-7; eval's L1 within 1e-5, lavapipe:
/// 4.7e-8), resumes exactly on the kernels,
/// and a run started there continues on the CPU.
#[test]
fn deep_shading_on_the_kernels_trains_as_on_the_cpu() {
    if !common::wgpu_runs() {
        return;
    }
    let (cpu, gpu, parts) = (
        fresh_dir("deep-cpu"),
        fresh_dir("deep-gpu"),
        fresh_dir("deep-gpu-parts"),
    );
    deep_shading(&cpu, "cpu", &["--epochs", "3"]);
    let log = deep_shading(&gpu, "wgpu", &["--epochs", "3"]);
    assert!(log.contains("GPU kernels on"), "{log}");
    let val = |d: &Path| losses(d).iter().filter_map(|r| r.1).collect::<Vec<_>>();
    let (a, b) = (val(&gpu), val(&cpu));
    let apart = a
        .iter()
        .zip(&b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs() / y));
    eprintln!("Deep Shading validation losses: kernels {a:?}, CPU {b:?}: {apart:.1e} apart");
    assert_eq!(a.len(), 3);
    assert!(apart < 1e-3, "kernels {a:?} against the CPU's {b:?}");
    deep_shading(&parts, "wgpu", &["--epochs", "1"]);
    let out = deep_shading(&parts, "wgpu", &["--epochs", "3"]);
    assert!(out.contains("resumed from epoch 1.00"), "{out}");
    let weights = |d: &Path| std::fs::read(d.join("weights.safetensors")).unwrap();
    assert!(weights(&gpu) == weights(&parts), "resumed weights differ");
    let out = deep_shading(&parts, "cpu", &["--epochs", "4"]);
    assert!(out.contains("resumed from epoch 3.00"), "{out}");
    assert_eq!(val(&parts).len(), 4);
    // `eval` shades its frames on the device it is given: the same metrics on both (beside a
    // design, which eval asks for).
    let design = fresh_dir("deep-beside");
    train(&design, "baseline", &["--epochs", "1", "--device", "cpu"]);
    let l1 = |device: &str| {
        let report = gpu.join(format!("eval-{device}"));
        ok(&[
            "eval",
            "--data",
            dataset().to_str().unwrap(),
            "--model",
            design.to_str().unwrap(),
            "--deep-shading",
            gpu.to_str().unwrap(),
            "--out",
            report.to_str().unwrap(),
            "--timing-res",
            "32",
            "--sh-spp",
            "4",
            "--temporal-frames",
            "0",
            "--device",
            device,
        ]);
        let results: serde_json::Value =
            serde_json::from_slice(&std::fs::read(report.join("results.json")).unwrap()).unwrap();
        let methods = results["methods"].as_array().unwrap();
        let m = methods
            .iter()
            .find(|m| m["name"] == "deep-shading")
            .unwrap();
        m["mean"]["l1"].as_f64().unwrap()
    };
    let (on_gpu, on_cpu) = (l1("wgpu"), l1("cpu"));
    eprintln!("Deep Shading's L1 in eval: kernels {on_gpu}, CPU {on_cpu}");
    assert!(
        (on_gpu - on_cpu).abs() <= 1e-5 * on_cpu,
        "{on_gpu} against {on_cpu}"
    );
    for d in [cpu, gpu, parts, design] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

/// `--precision f16` (mixed precision on the kernels) learns as f32 does: after the same
/// epochs from the same seed its last validation loss is at most 1% above f32's and every
/// epoch's within 5% of f32's (two runs' paths part a little on 3 views of 12², where the
/// validation loss rises again as they overfit; lavapipe: 2.1% apart at most, the last f16's
/// 2.1% below f32's), and it resumes exactly (its f16 weights are made again from the saved
/// f32 ones).
#[test]
fn mixed_precision_trains_as_f32_does() {
    if !common::wgpu_runs() {
        return;
    }
    let run = |precision: &str, epochs: &str, out: &Path| {
        let args = [
            "--epochs",
            epochs,
            "--batch-size",
            "256",
            "--encoding",
            "hash-grid",
            "--device",
            "wgpu",
            "--precision",
            precision,
            // A constant rate lets a finished run be lengthened.
            "--schedule",
            "paper",
            "--lr",
            "1e-3",
        ];
        train(out, "dsep", &args)
    };
    let full = fresh_dir("precision-f32");
    let mixed = fresh_dir("precision-f16");
    run("f32", "6", &full);
    let out = run("f16", "6", &mixed);
    assert!(out.contains("mixed precision"), "{out}");
    let val = |d: &Path| losses(d).iter().filter_map(|r| r.1).collect::<Vec<_>>();
    let (a, b) = (val(&mixed), val(&full));
    let first = (b[0] - b[b.len() - 1]) / b[0];
    let apart = a
        .iter()
        .zip(&b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs() / y));
    eprintln!("validation losses f16 {a:?}, f32 {b:?}: at most {apart:.1e} apart");
    assert!(first > 0.1, "f32 did not learn: {b:?}");
    assert!(apart < 0.05, "f16 {a:?} against f32 {b:?}");
    assert!(
        a[a.len() - 1] <= 1.01 * b[b.len() - 1],
        "f16 {a:?} against f32 {b:?}"
    );
    let resumed = fresh_dir("precision-f16-resumed");
    run("f16", "3", &resumed);
    let out = run("f16", "6", &resumed);
    assert!(out.contains("resumed from epoch 3.00"), "{out}");
    let weights = |d: &Path| std::fs::read(d.join("weights.safetensors")).unwrap();
    assert!(
        weights(&mixed) == weights(&resumed),
        "resumed weights differ"
    );
}

/// `--gather device` (the default: the dataset on the GPU, batches gathered there) trains as
/// `--gather host` (batches gathered here and uploaded) does: the device decodes the pack's
/// records in the host's f32 operations, rounded as it rounds a division, a square root or a
/// multiply-add, so every training and validation loss of two epochs agrees to 10⁻⁵
/// (lavapipe: 1.9·10⁻⁷).
#[test]
fn batches_gathered_on_the_gpu_equal_the_hosts() {
    if !common::wgpu_runs() {
        return;
    }
    let run = |gather: &str| {
        let out = fresh_dir(&format!("gather-{gather}"));
        let args = [
            "--epochs",
            "2",
            "--encoding",
            "hash-grid",
            "--device",
            "wgpu",
        ];
        let mut args = args.to_vec();
        args.extend(["--gather", gather]);
        train(&out, "dsep", &args);
        out
    };
    let (device, host) = (run("device"), run("host"));
    let flat = |d: &Path| -> Vec<f64> {
        losses(d)
            .into_iter()
            .flat_map(|(t, v)| t.into_iter().chain(v))
            .collect()
    };
    let (a, b) = (flat(&device), flat(&host));
    assert_eq!(a.len(), b.len());
    let worst = a
        .iter()
        .zip(&b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs() / y.abs()));
    eprintln!("gathered on the device against the host: losses within {worst:.1e}");
    assert!(worst < 1e-5, "{a:?} against {b:?}");
}

/// Each (design, encoding) of `cases` trained on `device` for `epochs` of one full batch: its
/// training loss falls below 0.03 and an eighth of its start.
fn overfits(cases: &[(&str, &str)], device: &str, epochs: usize) {
    let epochs_arg = epochs.to_string();
    for &(arch, encoding) in cases {
        let out = fresh_dir(&format!("overfit-{arch}-{encoding}-{device}"));
        // One full batch per epoch.
        train(
            &out,
            arch,
            &[
                "--epochs",
                &epochs_arg,
                "--lr",
                "1e-3",
                "--batch-size",
                "4096",
                "--encoding",
                encoding,
                "--device",
                device,
            ],
        );
        let rows = losses(&out);
        let train: Vec<f64> = rows.iter().filter_map(|r| r.0).collect();
        let first = train[..3].iter().sum::<f64>() / 3.0;
        let last = train[train.len() - 3..].iter().sum::<f64>() / 3.0;
        assert!(
            last < 0.03 && last < first / 8.0,
            "{arch}: training loss {first:.4} → {last:.4}"
        );
        assert!(
            rows.iter().filter(|r| r.1.is_some()).count() == epochs,
            "a validation loss per epoch"
        );
        let png = std::fs::read(out.join("loss.png")).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        let info = ok(&["model", "info", "--model", out.to_str().unwrap()]);
        assert!(info.contains(&format!("design {arch}")), "{info}");
        assert!(
            info.contains(&format!("position encoding {encoding}"))
                && info.contains("grid") == (encoding == "hash-grid"),
            "{info}"
        );
    }
}

#[test]
fn resumed_training_equals_an_uninterrupted_run() {
    resumes_exactly("cpu");
}

/// On `device`: a run stopped after an epoch and resumed to three equals three in one go, to
/// the bit; one seed gives one model, another seed another.
fn resumes_exactly(device: &str) {
    let straight = fresh_dir(&format!("resume-straight-{device}"));
    let resumed = fresh_dir(&format!("resume-parts-{device}"));
    // The paper's constant rate lets a finished run be lengthened; the hash grid's table and
    // its Adam moments must come back too.
    let paper = |epochs| {
        [
            "--epochs",
            epochs,
            "--schedule",
            "paper",
            "--encoding",
            "hash-grid",
            "--device",
            device,
        ]
    };
    train(&straight, "albedo", &paper("3"));
    train(&resumed, "albedo", &paper("1"));
    let out = train(&resumed, "albedo", &paper("3"));
    assert!(out.contains("resumed from epoch 1.00"), "{out}");
    let weights = |d: &Path| std::fs::read(d.join("weights.safetensors")).unwrap();
    assert!(
        weights(&straight) == weights(&resumed),
        "resumed weights differ"
    );
    let val = |d: &Path| losses(d).iter().filter_map(|r| r.1).collect::<Vec<_>>();
    assert_eq!(val(&straight), val(&resumed));
    // The same seed gives the same model; another seed another one.
    let again = fresh_dir(&format!("resume-again-{device}"));
    train(&again, "albedo", &paper("3"));
    assert!(weights(&again) == weights(&straight));
    let other = fresh_dir(&format!("resume-seed-{device}"));
    train(
        &other,
        "albedo",
        &["--epochs", "1", "--seed", "7", "--device", device],
    );
    let one = fresh_dir(&format!("resume-one-{device}"));
    train(&one, "albedo", &["--epochs", "1", "--device", device]);
    assert!(weights(&other) != weights(&one));
}

/// `--calibrate level` gives the saved model a gain per channel, its training targets' level
/// over its own; a finished run asked again follows the flag without training.
#[test]
fn a_model_is_calibrated_to_its_training_level_on_request() {
    let out = fresh_dir("calibrate");
    let gain = |d: &Path| -> Option<Vec<f64>> {
        let j: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join("model.json")).unwrap()).unwrap();
        j.get("level_gain").map(|g| {
            let g: Vec<f64> = g
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            assert_eq!(g.len(), 3);
            g
        })
    };
    let weights = |d: &Path| std::fs::read(d.join("weights.safetensors")).unwrap();
    let run = |calibrate| train(&out, "dsep", &["--epochs", "2", "--calibrate", calibrate]);
    let text = run("none");
    assert_eq!(gain(&out), None, "the paper's output by default");
    assert!(!text.contains("level gain"), "{text}");
    let trained = weights(&out);

    let text = run("level");
    assert!(text.contains("level gain"), "{text}");
    let g = gain(&out).expect("a gain once asked for");
    let info = ok(&["model", "info", "--model", out.to_str().unwrap()]);
    assert!(
        info.contains("output calibrated to its training level"),
        "{info}"
    );
    assert!(
        g.iter().all(|v| v.is_finite() && *v > 0.0) && g.iter().any(|v| *v != 1.0),
        "{g:?}"
    );
    assert!(weights(&out) == trained, "asking again does not train");
    // Measured on the same pixels of the same weights: the same gain every time.
    run("level");
    assert_eq!(gain(&out), Some(g));
    run("none");
    assert_eq!(gain(&out), None);
}

/// `nprt train-deep-shading` on the test dataset into `out` on `device`, with `extra` flags.
fn deep_shading(out: &Path, device: &str, extra: &[&str]) -> String {
    let data = dataset().to_str().unwrap();
    let mut args = vec![
        "train-deep-shading",
        "--data",
        data,
        "--out",
        out.to_str().unwrap(),
        "--encoder-width",
        "64",
        "--batch-views",
        "2",
        "--device",
        device,
    ];
    args.extend_from_slice(extra);
    ok(&args)
}

/// Deep Shading trains through the same loop: exact resume (Adam's moments included), the
/// same loss files, and a refusal to resume other settings.
#[test]
fn deep_shading_resumes_exactly_through_the_shared_loop() {
    let data = dataset().to_str().unwrap();
    let run = |out: &Path, extra: &[&str]| deep_shading(out, "cpu", extra);
    let straight = fresh_dir("deep-straight");
    let resumed = fresh_dir("deep-parts");
    run(&straight, &["--epochs", "3"]);
    run(&resumed, &["--epochs", "1"]);
    let out = run(&resumed, &["--epochs", "3"]);
    assert!(out.contains("resumed from epoch 1.00"), "{out}");
    let weights = |d: &Path| std::fs::read(d.join("weights.safetensors")).unwrap();
    assert!(
        weights(&straight) == weights(&resumed),
        "resumed Deep Shading weights differ"
    );
    let val = |d: &Path| losses(d).iter().filter_map(|r| r.1).collect::<Vec<_>>();
    assert_eq!(val(&straight).len(), 3);
    assert_eq!(val(&straight), val(&resumed));
    assert!(straight.join("checkpoint/state.json").exists());
    let config: serde_json::Value =
        serde_json::from_slice(&std::fs::read(straight.join("deep-shading.json")).unwrap())
            .unwrap();
    assert_eq!(config["epochs_done"], 3);
    fails(
        &[
            "train-deep-shading",
            "--data",
            data,
            "--out",
            straight.to_str().unwrap(),
            "--encoder-width",
            "64",
            "--batch-views",
            "3",
            "--epochs",
            "4",
        ],
        &["holds a run with other settings"],
    );
}

#[test]
fn bad_runs_stop_clearly_and_keep_the_last_good_checkpoint() {
    let data = dataset().to_str().unwrap();
    let out = fresh_dir("refuse");
    let o = out.to_str().unwrap();
    train(&out, "baseline", &["--epochs", "1"]);
    let state = std::fs::read(out.join("checkpoint/state.json")).unwrap();
    // Another design (or dataset, or hyper-parameters) in the same folder is refused.
    fails(
        &[
            "train",
            "--data",
            data,
            "--arch",
            "prt",
            "--out",
            o,
            "--encoder-width",
            "64",
        ],
        &["holds a run with other settings"],
    );
    // A learning rate that blows up stops with a clear message; the checkpoint is untouched.
    let boom = fresh_dir("diverge");
    let b = boom.to_str().unwrap();
    fails(
        &[
            "train",
            "--data",
            data,
            "--arch",
            "baseline",
            "--out",
            b,
            "--encoder-width",
            "64",
            "--lr",
            "1e4",
            "--epochs",
            "5",
        ],
        &["training diverged"],
    );
    assert_eq!(
        std::fs::read(out.join("checkpoint/state.json")).unwrap(),
        state
    );
    // Bad arguments and inputs.
    let bad = common::nprt(&["train", "--data", data, "--arch", "mlp", "--out", o]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("invalid value 'mlp'") && err.contains("[possible values: baseline, prt"),
        "{err}"
    );
    fails(
        &[
            "train",
            "--data",
            data,
            "--arch",
            "prt",
            "--out",
            o,
            "--encoder-width",
            "100",
        ],
        &["multiple of 64"],
    );
    fails(
        &[
            "train",
            "--data",
            data,
            "--arch",
            "prt",
            "--out",
            o,
            "--val-samples",
            "0",
        ],
        &["validation samples must be positive"],
    );
    fails(
        &[
            "train",
            "--data",
            data,
            "--arch",
            "prt",
            "--out",
            o,
            "--precision",
            "f16",
            "--device",
            "cpu",
        ],
        &["--precision f16 trains on nprt's own GPU kernels only"],
    );
    fails(
        &[
            "train",
            "--data",
            "/nonexistent/ds",
            "--arch",
            "prt",
            "--out",
            o,
        ],
        &["/nonexistent/ds"],
    );
    // A model of another version or whose weights belong to another design is refused.
    let json = std::fs::read_to_string(out.join("model.json")).unwrap();
    std::fs::write(
        out.join("model.json"),
        json.replace("\"version\": 1", "\"version\": 99"),
    )
    .unwrap();
    fails(&["model", "info", "--model", o], &["format version 99"]);
    std::fs::write(
        out.join("model.json"),
        json.replace("\"design\": \"baseline\"", "\"design\": \"prt\""),
    )
    .unwrap();
    fails(
        &["model", "info", "--model", o],
        &["belong to a 'baseline:relu' network, not 'prt:relu'"],
    );
    // The activation is recorded in the weights too: editing it is caught.
    std::fs::write(
        out.join("model.json"),
        json.replace("\"activation\": \"relu\"", "\"activation\": \"siren\""),
    )
    .unwrap();
    fails(
        &["model", "info", "--model", o],
        &["belong to a 'baseline:relu' network, not 'baseline:siren'"],
    );
}

/// `--minutes` stops a run at its budget (validated and saved there), and the same command
/// then has nothing left to do; a cosine run keeps its length and differs from the paper's.
#[test]
fn a_time_budget_stops_the_run_and_a_cosine_run_keeps_its_length() {
    let timed = fresh_dir("budget");
    let out = train(&timed, "prt", &["--minutes", "0.005"]);
    let state: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(timed.join("checkpoint/state.json")).unwrap(),
    )
    .unwrap();
    let seconds = state["seconds"].as_f64().unwrap();
    let steps = state["step"].as_u64().unwrap();
    assert!(
        (0.3..5.0).contains(&seconds) && steps > 0,
        "{seconds} s, {steps} steps: {out}"
    );
    assert!(
        losses(&timed).last().unwrap().1.is_some(),
        "validated at the budget"
    );
    let again = train(&timed, "prt", &["--minutes", "0.005"]);
    assert!(again.contains(&format!(" {steps} steps")), "{again}");

    let cosine = fresh_dir("cosine");
    let paper = fresh_dir("cosine-paper");
    train(
        &cosine,
        "prt",
        &["--epochs", "2", "--schedule", "cosine", "--lr", "1e-3"],
    );
    train(
        &paper,
        "prt",
        &["--epochs", "2", "--lr", "1e-3", "--schedule", "paper"],
    );
    let weights = |d: &Path| std::fs::read(d.join("weights.safetensors")).unwrap();
    assert!(weights(&cosine) != weights(&paper));
    fails(
        &train_args(
            &cosine,
            "prt",
            &["--epochs", "3", "--schedule", "cosine", "--lr", "1e-3"],
        ),
        &["decaying --schedule"],
    );
}

#[test]
fn a_dataset_is_packed_once_and_again_only_when_it_changes() {
    let dir = fresh_dir("pack-data");
    common::room_dataset(&dir, [2, 1], 10, 4);
    let d = dir.to_str().unwrap();
    let pack = |args: &[&str]| {
        let o = common::nprt(args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        (
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (out, err) = pack(&["dataset", "pack", d]);
    assert!(err.contains(&format!("packing '{d}'")), "{err}");
    assert!(
        out.contains("packed-radiance.bin") && out.contains("of 3 views"),
        "{out}"
    );
    let (_, err) = pack(&["dataset", "pack", d]);
    assert!(
        !err.contains("packing"),
        "a current pack is used as it is: {err}"
    );
    assert!(ok(&["dataset", "verify", d]).contains("packed-radiance.bin: current"));

    // A view redone after packing: verify says so, and training packs again before it reads.
    let view = dir.join("views").join("train_00001.exr");
    let bytes = std::fs::read(&view).unwrap();
    std::thread::sleep(std::time::Duration::from_millis(20));
    std::fs::write(&view, bytes).unwrap();
    assert!(ok(&["dataset", "verify", d]).contains("out of date"));
    let model = fresh_dir("pack-model");
    let (_, err) = pack(&[
        "train",
        "--data",
        d,
        "--arch",
        "baseline",
        "--out",
        model.to_str().unwrap(),
        "--encoder-width",
        "64",
        "--batch-size",
        "64",
        "--epochs",
        "1",
    ]);
    assert!(err.contains("again: a view file changed"), "{err}");
    // Models that trace the direct light learn from their own pack.
    let (_, err) = pack(&["dataset", "pack", d, "--direct", "traced"]);
    assert!(err.contains("packing"), "{err}");
    assert!(dir.join("packed-indirect.bin").exists());
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_dir_all(&model).unwrap();
}

/// A checkpoint is one format on both engines (the weights, and Adam's moments in the
/// network's tensor order): a run started on the CPU engine continues on the GPU kernels and
/// back, each leg resuming where the last stopped.
fn resumes_across_engines() {
    let out = fresh_dir("resume-across-engines");
    let run = |epochs: &str, device: &str| {
        let args = [
            "--epochs",
            epochs,
            "--schedule",
            "paper",
            "--device",
            device,
        ];
        train(&out, "albedo", &args)
    };
    run("1", "cpu");
    for (epochs, device, from) in [("2", "wgpu", "1.00"), ("3", "cpu", "2.00")] {
        let log = run(epochs, device);
        assert!(log.contains(&format!("resumed from epoch {from}")), "{log}");
    }
    let val: Vec<f64> = losses(&out).iter().filter_map(|r| r.1).collect();
    assert_eq!(val.len(), 3, "one validation row per epoch: {val:?}");
    assert!(val.iter().all(|v| v.is_finite()), "{val:?}");
}

/// `--pause-after` stops a call, saved, inside the run (its length and its cosine schedule over
/// --minutes kept); the same command continues it from there, and the call that reaches the
/// run's end is not said to pause.
#[test]
fn a_paused_run_is_continued_by_the_same_command() {
    let out = fresh_dir("pause");
    let seconds = || -> f64 {
        let state = std::fs::read_to_string(out.join("checkpoint/state.json")).unwrap();
        serde_json::from_str::<serde_json::Value>(&state).unwrap()["seconds"]
            .as_f64()
            .unwrap()
    };
    let run = |pause: &[&str]| {
        let mut args = vec!["--minutes", "0.1", "--checkpoint-minutes", "0"];
        args.extend_from_slice(pause);
        train(&out, "baseline", &args)
    };
    let first = run(&["--pause-after", "0.02"]);
    assert!(first.contains("paused (--pause-after 0.02)"), "{first}");
    let after_first = seconds();
    assert!((1.2..6.0).contains(&after_first), "{after_first} s");
    let second = run(&["--pause-after", "0.02"]);
    assert!(second.contains("resumed from epoch"), "{second}");
    assert!(second.contains("paused (--pause-after"), "{second}");
    assert!(seconds() >= after_first + 1.2, "{} s", seconds());
    let last = run(&[]);
    assert!(!last.contains("paused"), "{last}");
    assert!(seconds() >= 6.0, "{} s", seconds());
    fails(
        &train_args(
            &out,
            "baseline",
            &["--minutes", "0.1", "--pause-after", "0"],
        ),
        &["the pause (--pause-after) 0 is not a number of minutes from 0.001"],
    );
    std::fs::remove_dir_all(&out).ok();
}

/// Without `--arch`, the recommended recipe (nprt_net::RECIPE) with its own settings, said in
/// one line; with it, the named design with the paper's.
#[test]
fn without_arch_it_trains_the_recommended_recipe_and_says_so() {
    let dir = fresh_dir("recipe");
    let model = dir.join("recipe");
    let mut args = train_args(&model, "linear", &["--epochs", "1"]);
    let arch = args.iter().position(|a| *a == "--arch").unwrap();
    args.drain(arch..arch + 2);
    let out = ok(&args);
    let manifest = std::fs::read_to_string(dataset().join("manifest.json")).unwrap();
    let targets = match manifest.contains(r#""transfer": "sh:"#) {
        true => "transfer vectors",
        false => "radiance",
    };
    let line = format!(
        "training the recommended recipe: linear design on sh:2 (siren), direct light traced, \
         on {targets}, level calibrated"
    );
    assert!(out.contains(&line), "no '{line}' in:\n{out}");
    let config = std::fs::read_to_string(model.join("model.json")).unwrap();
    for needle in [
        r#""design": "linear""#,
        r#""basis": "sh:2""#,
        r#""direct": "traced""#,
        r#""level_gain""#,
    ] {
        assert!(config.contains(needle), "no {needle} in {config}");
    }
    // A design named keeps its own defaults: the paper's D/S learns all its light, raw.
    let dsep = dir.join("dsep");
    let out = train(&dsep, "dsep", &["--epochs", "1"]);
    assert!(
        out.contains("training dsep design (siren), direct light learned, on radiance\n"),
        "{out}"
    );
    let config = std::fs::read_to_string(dsep.join("model.json")).unwrap();
    assert!(
        !config.contains("level_gain") && !config.contains(r#""direct""#),
        "{config}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
