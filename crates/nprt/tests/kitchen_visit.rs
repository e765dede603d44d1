//! bench/kitchen-visit.sh, the GPU visit's script: what `land` refuses, and how `run` goes on
//! when a tensor-core kernel fails its correctness tests on the visit's device (a copy of the
//! script in a scratch folder, with stand-ins for the bundle's binaries and for training).

mod common;

use common::fresh_dir;
use std::os::unix::fs::PermissionsExt;
use std::path::Path;

/// bench/kitchen-visit.sh's `land` names what it cannot land before it changes anything: no
/// folder, a folder without a visit's model, a CPU model to compare that is not a model; and the
/// CPU-trained D/S it compares by default is in the repository.
#[test]
fn the_visit_script_refuses_what_it_cannot_land() {
    let run = |args: &[&str]| common::script("bench/kitchen-visit.sh", args);
    let empty = fresh_dir("visit-empty");
    std::fs::create_dir_all(&empty).unwrap();
    let empty = empty.to_str().unwrap();
    for (args, why) in [
        (
            &["land"][..],
            "give the folder a visit's files came back to",
        ),
        (
            &["land", empty],
            "holds no model.tar.xz (did the visit train?)",
        ),
        (&["land", empty, "--cpu-model", empty], "--cpu-model: '"),
        (
            &["land", empty, "--frobnicate"],
            "unknown argument '--frobnicate'",
        ),
    ] {
        let out = run(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(why), "{args:?}: {err}");
    }
    let cpu = common::repo().join("pretrained/kitchen-dsep/cpu-f32");
    let config: serde_json::Value =
        serde_json::from_slice(&std::fs::read(cpu.join("model.json")).unwrap()).unwrap();
    assert_eq!(config["design"], "dsep");
    assert!(cpu.join("weights.safetensors").is_file());
    std::fs::remove_dir_all(empty).unwrap();
}

/// An executable shell script at `path`.
fn script_at(path: &Path, body: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, format!("#!/bin/sh\n{body}\n")).unwrap();
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// `run` with a correctness test that passes always, only on the plain kernels
/// (`NPRT_TENSOR_CORES=off`), or never: it trains as it is, trains on the plain kernels after
/// saying so in the summary, or stops before training, naming why. Training is a stand-in
/// that notes the switch it was given and stops the script.
#[test]
fn a_visit_whose_tensor_core_kernels_fail_trains_on_the_plain_ones() {
    let repo = common::repo();
    for (case, test, trained) in [
        ("passes", "true", Some("unset")),
        ("plain", "[ \"$NPRT_TENSOR_CORES\" = off ]", Some("off")),
        ("fails", "false", None),
    ] {
        let dir = fresh_dir(&format!("visit-{case}"));
        for name in ["kitchen-visit.sh", "gpu-vulkan.sh"] {
            std::fs::create_dir_all(dir.join("bench")).unwrap();
            std::fs::copy(repo.join("bench").join(name), dir.join("bench").join(name)).unwrap();
        }
        let mark = dir.join("trained-with");
        script_at(
            &dir.join("bench/kitchen.sh"),
            &format!(
                "echo \"${{NPRT_TENSOR_CORES:-unset}}\" > {}; exit 3",
                mark.display()
            ),
        );
        script_at(&dir.join(".visit/gpu/nprt"), "exit 0");
        script_at(
            &dir.join(".visit/gpu/tests/kernels"),
            &format!(
                "if {test}; then echo 'test result: ok. 1 passed'; \
                 else echo 'test result: FAILED. 0 passed; 1 failed'; exit 101; fi"
            ),
        );
        std::fs::create_dir_all(dir.join(".visit/kitchen")).unwrap();
        std::fs::write(dir.join(".visit/kitchen/scene.xml"), "").unwrap();
        let out = std::process::Command::new("bash")
            .arg(dir.join("bench/kitchen-visit.sh"))
            .args(["run", "--minutes", "5"])
            .env("OUT", dir.join("out"))
            .env("VISIT_PRETRAINED", dir.join("pretrained"))
            .env_remove("NPRT_TENSOR_CORES")
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned()
            + &String::from_utf8_lossy(&out.stderr);
        let summary = std::fs::read_to_string(dir.join("out/summary.md")).unwrap();
        let got = std::fs::read_to_string(&mark).ok();
        assert_eq!(got.as_deref().map(str::trim), trained, "{case}: {text}");
        let plain = summary.contains("This visit ran on the plain kernels (NPRT_TENSOR_CORES=off)");
        assert_eq!(plain, case == "plain", "{case}: {summary}");
        match trained {
            // The stand-in's exit ends the script.
            Some(_) => assert_eq!(out.status.code(), Some(3), "{case}: {text}"),
            None => {
                assert_eq!(out.status.code(), Some(1), "{case}: {text}");
                assert!(
                    text.contains("a test failed on the plain kernels too"),
                    "{case}: {text}"
                );
            }
        }
        std::fs::remove_dir_all(dir).unwrap();
    }
}

/// Copies the model folder `from` to `to` (files and checkpoint/).
fn copy_model(from: &Path, to: &Path) {
    std::fs::create_dir_all(to.join("checkpoint")).unwrap();
    for sub in ["", "checkpoint"] {
        for e in std::fs::read_dir(from.join(sub)).unwrap().flatten() {
            if e.file_type().unwrap().is_file() {
                std::fs::copy(e.path(), to.join(sub).join(e.file_name())).unwrap();
            }
        }
    }
}

/// What the run folder holds, to show a refused landing changed nothing.
fn run_bytes(run: &Path) -> Vec<Vec<u8>> {
    [
        "visits.csv",
        "model/weights.safetensors",
        "model/model.json",
    ]
    .iter()
    .map(|f| std::fs::read(run.join(f)).unwrap())
    .collect()
}

/// `nprt model land` (the script's landing) checks a visit's model whole before the run's
/// folder changes: a model without its checkpoint, with a NaN weight, with a training time of
/// NaN, without a validation loss, or behind the last visit is refused naming why, and the
/// run's model and visits.csv stay as they were; a good one lands with its row.
#[test]
fn a_visit_s_model_lands_whole_or_changes_nothing() {
    let dir = fresh_dir("visit-land");
    let model = common::tiny_room_model(&dir, &["--arch", "baseline"]);
    let run = dir.join("run");
    let land = |m: &Path| {
        common::nprt(&[
            "model",
            "land",
            m.to_str().unwrap(),
            "--into",
            run.to_str().unwrap(),
            "--landed",
            "2026-11-29T12:00Z",
        ])
    };
    let o = land(&model);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let row = String::from_utf8_lossy(&o.stdout).trim().to_string();
    assert!(row.starts_with("2026-11-29T12:00Z,"), "{row}");
    let table = std::fs::read_to_string(run.join("visits.csv")).unwrap();
    assert_eq!(table.lines().count(), 2, "{table}");
    assert!(run.join("model/checkpoint/state.json").is_file());
    let before = run_bytes(&run);

    let state = |m: &Path| m.join("checkpoint/state.json");
    let edited = |name: &str, edit: &dyn Fn(&Path)| {
        let m = dir.join(name);
        copy_model(&model, &m);
        edit(&m);
        m
    };
    let no_checkpoint = edited("no-ck", &|m| {
        std::fs::remove_dir_all(m.join("checkpoint")).unwrap()
    });
    let nan_weight = edited("nan", &|m| {
        let path = m.join("weights.safetensors");
        let mut bytes = std::fs::read(&path).unwrap();
        let n = bytes.len();
        bytes[n - 4..].copy_from_slice(&f32::NAN.to_le_bytes());
        std::fs::write(&path, bytes).unwrap();
    });
    let nan_seconds = edited("nan-seconds", &|m| {
        let text = std::fs::read_to_string(state(m)).unwrap();
        let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
        json["seconds"] = serde_json::json!("S");
        std::fs::write(state(m), json.to_string().replace("\"S\"", "NaN")).unwrap();
    });
    let no_val = edited("no-val", &|m| {
        let text = std::fs::read_to_string(state(m)).unwrap();
        let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
        for row in json["history"].as_array_mut().unwrap() {
            row["val"] = serde_json::Value::Null;
        }
        std::fs::write(state(m), json.to_string()).unwrap();
    });
    // The run's last visit has seen more than this model.
    let behind = dir.join("behind-run");
    std::fs::create_dir_all(&behind).unwrap();
    for (m, why) in [
        (&no_checkpoint, "holds no checkpoint/"),
        (&nan_weight, "tensor"),
        (&nan_seconds, "malformed"),
        (&no_val, "holds no validation loss"),
    ] {
        let o = land(m);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{why}: {err}");
        assert!(err.contains(why), "{why}: {err}");
        assert_eq!(run_bytes(&run), before, "{why}");
    }
    // Into the model's own folder (it was copied into itself until the names grew too long), or
    // into a file.
    let file = run.join("visits.csv");
    for (into, why) in [(&model, "is the model folder"), (&file, "is not a folder")] {
        let o = common::nprt(&[
            "model",
            "land",
            model.to_str().unwrap(),
            "--into",
            into.to_str().unwrap(),
            "--landed",
            "2026-11-29T12:00Z",
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(why), "{why}: {err}");
        assert_eq!(run_bytes(&run), before, "{why}");
    }
    assert!(!model.join("model").exists());
    let table = format!(
        "{}\n2026-11-29T12:05Z,99,999999999,9,0.01\n",
        table.trim_end()
    );
    std::fs::write(run.join("visits.csv"), &table).unwrap();
    let o = land(&model);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("does not continue the run"), "{err}");
    assert_eq!(
        std::fs::read_to_string(run.join("visits.csv")).unwrap(),
        table
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
