//! `nprt train --snapshots`: the model kept at each point of a run is the model a run stopped
//! there ends with, loadable as any model folder; resumed runs keep what they have.

mod common;

use std::path::Path;

use common::{fresh_dir, nprt, ok};

fn train(data: &Path, out: &Path, extra: &[&str]) -> String {
    #[rustfmt::skip]
    let mut args = vec![
        "train", "--data", data.to_str().unwrap(), "--arch", "albedo", "--out",
        out.to_str().unwrap(), "--encoder-width", "64", "--batch-size", "64",
        "--views-per-batch", "3", "--val-samples", "256", "--schedule", "paper",
    ];
    args.extend_from_slice(extra);
    let o = nprt(&args);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{args:?}: {err}");
    err
}

fn weights(dir: &Path) -> Vec<u8> {
    std::fs::read(dir.join("weights.safetensors")).unwrap()
}

#[test]
fn snapshots_are_the_models_of_their_points() {
    let dir = fresh_dir("snapshots");
    let data = dir.join("data");
    common::room_dataset(&data, [3, 1], 12, 16);
    // Kept at epochs 1 and 2 of 3: the models runs of 1 and 2 epochs end with (the paper's
    // constant rate: a run's first epochs do not depend on its length).
    let three = dir.join("three");
    train(
        &data,
        &three,
        &["--epochs", "3", "--snapshots", "2,0.001m,1"],
    );
    for (point, epochs) in [("1", "1"), ("2", "2")] {
        let alone = dir.join(format!("alone{point}"));
        train(&data, &alone, &["--epochs", epochs]);
        let kept = three.join("snapshots").join(point);
        assert!(weights(&kept) == weights(&alone), "snapshot {point}");
        ok(&["model", "info", "--model", kept.to_str().unwrap()]);
    }
    assert!(three.join("snapshots/0.001m/model.json").is_file());
    assert!(
        !three.join("snapshots/1/checkpoint").exists(),
        "no optimiser state"
    );
    // A run resumed keeps what it has; a point it passed before being asked is not kept later.
    let parts = dir.join("parts");
    train(&data, &parts, &["--epochs", "1"]);
    let err = train(&data, &parts, &["--epochs", "3", "--snapshots", "1,3"]);
    assert!(err.contains("snapshot 1: the run passed it"), "{err}");
    assert!(!parts.join("snapshots/1").exists());
    assert!(weights(&parts.join("snapshots/3")) == weights(&parts));
    // A point left broken (its weights without model.json, as a build that wrote in place left
    // it when killed between the two) and a killed run's temporary: the point is taken again.
    let broken = dir.join("broken");
    train(&data, &broken, &["--epochs", "1"]);
    std::fs::create_dir_all(broken.join("snapshots/.2.999.tmp")).unwrap();
    std::fs::create_dir_all(broken.join("snapshots/2")).unwrap();
    std::fs::copy(
        broken.join("weights.safetensors"),
        broken.join("snapshots/2/weights.safetensors"),
    )
    .unwrap();
    train(&data, &broken, &["--epochs", "3", "--snapshots", "2"]);
    ok(&[
        "model",
        "info",
        "--model",
        broken.join("snapshots/2").to_str().unwrap(),
    ]);
    assert!(weights(&broken.join("snapshots/2")) == weights(&dir.join("alone2")));
    let left: Vec<_> = std::fs::read_dir(broken.join("snapshots"))
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect();
    assert_eq!(left, ["2"]);
    for bad in ["0m", "1,1", "1.5", "soon", "1e-300m", "2,1,2"] {
        let o = nprt(&[
            "train",
            "--data",
            "d",
            "--arch",
            "dsep",
            "--out",
            "m",
            "--snapshots",
            bad,
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad}: {err}");
        assert!(err.contains("--snapshots"), "{bad}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
