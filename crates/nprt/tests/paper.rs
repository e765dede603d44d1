//! `nprt paper --budget tiny` end to end on builtin:room: its dataset rendered from the flags
//! it prints, every table of the paper in one report with finite figures and the paper's
//! columns, a repeated run resumed from its caches, the orderings judged at snapshots of the
//! training, and a folder of another experiment refused.

mod common;

use common::{fails, fresh_dir, nprt, ok};

/// One tiny run serves every check of a finished experiment (each run trains and evaluates the
/// whole experiment again): its dataset rendered from the flags it prints (the cluster route),
/// its tables, and what its re-runs resume or redo.
#[test]
fn the_tiny_budget_writes_every_table_and_resumes() {
    let dir = fresh_dir("paper");
    let out = dir.to_str().unwrap();
    let args = ["paper", "--budget", "tiny", "--out", out, "--device", "cpu"];
    let stdout = run_from_printed_flags(&args);
    assert!(stdout.contains("the paper's orderings here: "), "{stdout}");
    let report = dir.join("report");
    let md = std::fs::read_to_string(report.join("paper.md")).unwrap();
    // The design beyond the paper is saved with its level calibrated (its measured recipe); the
    // paper's designs keep their raw output.
    let config = |name: &str| {
        std::fs::read_to_string(dir.join("models").join(name).join("model.json")).unwrap()
    };
    assert!(config("linear+sh:2+direct").contains("\"level_gain\""));
    assert!(!config("dsep").contains("\"level_gain\""));
    for want in [
        "## What this run says",
        "## Table 1: transport parameters",
        "| model | nprt | paper |",
        // The paper's parameter counts beside nprt's.
        "| nprt-baseline | 219651 | 219651 |",
        "| nprt-prt | 186947 | 186947 |",
        "| nprt-albedo | 187718 | 187718 |",
        "| nprt-baseline+siren | 219651 | – |",
        "## Table 2: SIREN or ReLU",
        "| baseline (R) | nprt-baseline |",
        "| baseline (S) | nprt-baseline+siren |",
        "| PRT-inspired (R) | nprt-prt+relu |",
        "| PRT-inspired (S) | nprt-prt |",
        "**SIREN helps the PRT-inspired design**",
        "**baseline (S) is highest**",
        "## Tables 3 and 4",
        "| nprt-dsep: network |",
        "| 16.02 |",
        "| 19–36 (Falcor) |",
        "## Table 5: the four designs",
        "| design | loss × 10³ | RMSE × 10³ | RMSE / D/S's |",
        // The paper's own figures beside nprt's, its scenes labelled as the paper's.
        "The paper's Table 5 in its four scenes (none of them is this run's scene)",
        "| paper ATELIER loss × 10³ | RMSE × 10³ | loss / PRT (S)'s | RMSE / PRT (S)'s |",
        "| Ours (D/S) | 30.23 | 5.34 | 63.95 | 80.46 | 22.02 | 1.000 |",
        "## The paper's orderings in its own figures",
        "- Table 5, KITCHEN, RMSE: D/S lowest holds; albedo ≤ PRT-inspired < baseline fails.",
        "- Table 6, BEDROOM: D/S lowest in every metric fails (MRSE: PRT-25 19.62 against 21.76).",
        "**D/S is lowest of the four designs**",
        "## Table 6: D/S against every competitor",
        "| method | L1 × 10³ | L2 × 10³ | dSSIM × 10³ | MAPE × 10³ | MRSE × 10³ |",
        // The linear design beyond the paper has its row beside D/S, said to be beyond it.
        "| nprt-linear+sh:2+direct |",
        "nprt-linear+sh:2+direct is beyond the paper",
        "**D/S is ahead of deep-shading on the test views**",
        "**D/S is ahead of nrc along the camera path**",
        "**D/S is ahead of nrc-cache along the camera path**",
        "## Figures 7 and 9: crops at the same pixels",
        "-nprt-dsep-crop.png",
        "images/table2-validation.png",
        "## Where the paper's figures come from",
        "| **all** |",
    ] {
        assert!(md.contains(want), "paper.md lacks '{want}':\n{md}");
    }
    // The paper's Table 5 as ../shared/paper-tables.md prints it: its KITCHEN row's figures,
    // each design's loss and RMSE, are in paper.md.
    if let Some(tables) = common::shared("paper-tables.md") {
        let tables = std::fs::read_to_string(tables).unwrap();
        let row = tables
            .lines()
            .find(|l| l.starts_with("| KITCHEN |"))
            .expect("Table 5's KITCHEN row");
        let figures: Vec<&str> = row
            .split('|')
            .map(str::trim)
            .filter(|c| !c.is_empty())
            .skip(1)
            .collect();
        assert_eq!(figures.len(), 8, "{row}");
        for pair in figures.chunks(2) {
            let cells = format!("| {} | {} |", pair[0], pair[1]);
            assert!(md.contains(&cells), "paper.md lacks KITCHEN's {cells}");
        }
    }
    // Every mean ± standard error is a finite number (4 test views give a standard error).
    let figures: Vec<(f64, f64)> = md
        .lines()
        .filter(|l| l.starts_with('|'))
        .flat_map(|l| l.split('|'))
        .filter_map(|c| {
            let (m, s) = c.trim().split_once(" ± ")?;
            Some((m.parse().expect(m), s.parse().expect(s)))
        })
        .collect();
    // Table 2: 4 rows × 2; Table 5: 4 × 2; Table 6: the test views' rows and the path's × 5.
    assert!(
        figures.len() >= 8 + 8 + 5 * 5,
        "{} figures:\n{md}",
        figures.len()
    );
    for (m, s) in &figures {
        assert!(
            m.is_finite() && s.is_finite() && *m >= 0.0 && *s >= 0.0,
            "{m} ± {s}"
        );
    }
    // Each ordering's verdict is one of the three marks.
    let judged = md
        .lines()
        .filter(|l| l.starts_with("- ") && l.contains("**"))
        .count();
    assert!(judged >= 4 + 2 + 5, "{judged} orderings judged:\n{md}");
    let html = std::fs::read_to_string(report.join("paper.html")).unwrap();
    assert!(
        !html.contains("src=\"images/") && html.matches("data:image/png;base64,").count() > 20,
        "paper.html must embed its images"
    );

    // Run again: every stage is found done, the evaluation read back rather than repeated.
    let again = ok(&args);
    assert!(again.contains("its inputs are unchanged"), "{again}");
    assert_eq!(
        std::fs::read_to_string(report.join("paper.md")).unwrap(),
        md,
        "a resumed run writes the same tables"
    );
    // A report rewritten by hand (an evaluation of one view into the same folder) is not taken
    // for the run's own: the run evaluates again.
    let models = dir.join("models");
    let model = |name: &str| models.join(name).to_str().unwrap().to_string();
    let data = dir.join("dataset");
    ok(&[
        "eval",
        "--data",
        data.to_str().unwrap(),
        "--model",
        &model("dsep"),
        "--views",
        "1",
        "--out",
        report.to_str().unwrap(),
        "--temporal-frames",
        "0",
        "--device",
        "cpu",
    ]);
    let redone = ok(&args);
    assert!(!redone.contains("its inputs are unchanged"), "{redone}");
    let md = std::fs::read_to_string(report.join("paper.md")).unwrap();
    assert!(!md.contains(" 1 test views"), "{md}");
    // Pictures gone: evaluated again too.
    std::fs::remove_dir_all(report.join("images")).unwrap();
    let redone = ok(&args);
    assert!(!redone.contains("its inputs are unchanged"), "{redone}");
    assert!(report.join("images").is_dir());
    // A stage time no run takes, read back, is refused by file.
    let times = dir.join("stage-times.json");
    let kept = std::fs::read_to_string(&times).unwrap();
    let forged: serde_json::Value = serde_json::from_str(&kept).unwrap();
    for secs in [1e308, -3600.0] {
        let mut forged = forged.clone();
        forged[0][1] = serde_json::json!(secs);
        std::fs::write(&times, forged.to_string()).unwrap();
        fails(&args, &["stage-times.json", "which no run takes"]);
    }
    std::fs::write(&times, kept).unwrap();

    // Another budget in the same folder is refused, naming both.
    fails(
        &[
            "paper", "--budget", "small", "--out", out, "--device", "cpu",
        ],
        &[
            "holds another experiment",
            "\"budget\":\"tiny\"",
            "\"budget\":\"small\"",
        ],
    );
    // So is a longer training at the same budget: the record holds it once given.
    #[rustfmt::skip]
    let longer = ["paper", "--budget", "tiny", "--out", out, "--device", "cpu", "--training-minutes", "0.5"];
    fails(
        &longer,
        &["holds another experiment", "\"training_minutes\":0.5"],
    );
    let o = nprt(&["paper", "--budget", "huge", "--out", out]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("unknown budget 'huge'"),
        "{err}"
    );
}

/// The cluster route: `nprt generate` with the flags `--generate-flags` prints (as
/// scripts/slurm-generate runs it), then the `nprt paper` of `args` finds every view done.
/// What that run printed.
fn run_from_printed_flags(args: &[&str]) -> String {
    let flags = ok(&[args, &["--generate-flags"]].concat());
    let flags: Vec<&str> = flags.split_whitespace().collect();
    assert!(
        flags.contains(&"--train-views") && flags.contains(&"24"),
        "{flags:?}"
    );
    ok(&[&["generate"], &flags[..]].concat());
    let run = ok(args);
    assert!(
        run.contains("0 views rendered") && run.contains("28 already complete"),
        "{run}"
    );
    run
}

/// A run refused before its dataset exists claims nothing (the corrected command is not
/// refused for a setting it no longer asks), and an output path that is not UTF-8 is refused
/// by its flag before any work.
#[test]
fn a_refused_run_claims_nothing_and_paths_must_be_utf8() {
    let dir = fresh_dir("paper-claim");
    let out = dir.to_str().unwrap();
    fails(
        &[
            "paper",
            "--budget",
            "tiny",
            "--out",
            out,
            "--device",
            "cpu",
            "--scene",
            "no-such-scene.xml",
        ],
        &["no-such-scene.xml"],
    );
    assert!(!dir.join("experiment.json").exists());
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let odd = dir.join(std::ffi::OsStr::from_bytes(b"out\xff"));
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_nprt"))
            .args(["paper", "--budget", "tiny", "--device", "cpu", "--out"])
            .arg(&odd)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(
            err.contains("--out") && err.contains("not valid UTF-8"),
            "{err}"
        );
        assert!(!odd.exists(), "nothing is made for a refused path");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `--snapshots`: the four designs kept at each point of their training, scored, the orderings
/// of Tables 5 and 6 judged at each point and plotted against training time; read back on a
/// repeated run.
#[test]
fn orderings_are_judged_as_training_grows() {
    let dir = fresh_dir("paper-snapshots");
    let out = dir.to_str().unwrap();
    #[rustfmt::skip]
    let args = ["paper", "--budget", "tiny", "--out", out, "--device", "cpu", "--snapshots", "1,2,99"];
    ok(&args);
    let report = dir.join("report");
    let md = std::fs::read_to_string(report.join("paper.md")).unwrap();
    let section = &md[md
        .find("## The orderings as training grows")
        .expect("the section")..];
    for want in [
        "| point | training min | nprt-baseline | nprt-prt | nprt-albedo | nprt-dsep |",
        "| 1 | ",
        "| 2 | ",
        "| table | ordering | 1 | 2 | holds from |",
        "| Table 5 | D/S is lowest of the four designs |",
        "| Table 6 | D/S is ahead of sh-prt-9 on the test views |",
        "images/growth-rmse.png",
        "images/growth-loss.png",
    ] {
        assert!(section.contains(want), "lacks '{want}':\n{section}");
    }
    // A point the two-epoch budget never reaches is no row.
    assert!(!section.contains("| 99 |"), "{section}");
    for plot in ["growth-rmse.png", "growth-loss.png"] {
        assert!(report.join("images").join(plot).is_file(), "{plot}");
    }
    // The last point's D/S is the final D/S (two epochs): its figures are the final row's.
    let points: serde_json::Value =
        serde_json::from_slice(&std::fs::read(report.join("snapshots.json")).unwrap()).unwrap();
    let results: serde_json::Value =
        serde_json::from_slice(&std::fs::read(report.join("results.json")).unwrap()).unwrap();
    let ds = |rows: &serde_json::Value| {
        rows.as_array()
            .unwrap()
            .iter()
            .find(|m| m["name"] == "nprt-dsep")
            .unwrap()["per_view"]
            .clone()
    };
    assert_eq!(ds(&points[1]["rows"]), ds(&results["methods"]));
    let again = ok(&args);
    assert!(again.contains("its inputs are unchanged"), "{again}");
    assert_eq!(
        std::fs::read_to_string(report.join("paper.md")).unwrap(),
        md
    );
    std::fs::remove_dir_all(&dir).ok();
}
