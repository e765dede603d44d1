//! `nprt generate` as a Slurm job array (scripts/slurm-generate) on a real single-node cluster
//! (scripts/slurm.sh starts one; scripts/test requires it): the array's dataset is byte-identical
//! to one unsharded run, and a task killed mid-shard is requeued and completes it with nothing
//! lost. Skipped where no cluster answers, unless NPRT_REQUIRE_SLURM is set.

mod common;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{fresh_dir, ok};

/// Whether the single-node test cluster of scripts/slurm.sh answers here (another cluster's
/// nodes would not see this machine's /tmp); where NPRT_REQUIRE_SLURM is set it must.
fn slurm_runs() -> bool {
    let idle = Command::new("scontrol")
        .args(["show", "config"])
        .output()
        .is_ok_and(|o| {
            let config = String::from_utf8_lossy(&o.stdout);
            o.status.success()
                && config.lines().any(|l| {
                    l.split_whitespace().collect::<Vec<_>>() == ["ClusterName", "=", "nprt-test"]
                })
        });
    if !idle {
        assert!(
            std::env::var_os("NPRT_REQUIRE_SLURM").is_none(),
            "NPRT_REQUIRE_SLURM is set but scripts/slurm.sh's test cluster (nprt-test) does not answer"
        );
        eprintln!("SKIPPED: scripts/slurm.sh's test cluster (nprt-test) does not answer here");
    }
    idle
}

/// The flags of a small dataset whose views take long enough (`spp`) to be killed mid-shard.
fn flags(out: &Path, spp: &str) -> Vec<String> {
    [
        "--scene",
        "builtin:room",
        "--envmaps",
        "builtin",
        "--train-views",
        "10",
        "--test-views",
        "2",
        "--train-res",
        "24",
        "--test-res",
        "24",
        "--spp",
        spp,
        "--test-spp",
        spp,
        "--out",
        out.to_str().unwrap(),
    ]
    .map(String::from)
    .into()
}

/// The views of a dataset folder, by name, with their bytes.
fn views(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<_> = std::fs::read_dir(dir.join("views"))
        .unwrap()
        .map(|e| e.unwrap())
        .map(|e| {
            (
                e.file_name().into_string().unwrap(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

/// Starts scripts/slurm-generate with `shards` tasks and --wait; returns it and the array's id.
fn submit(shards: &str, out: &Path, spp: &str) -> (std::process::Child, String) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/slurm-generate");
    let mut child = Command::new(script)
        .args([shards, "--wait", "--"])
        .args(flags(out, spp))
        .env("NPRT", env!("CARGO_BIN_EXE_nprt"))
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.as_mut().unwrap())
        .read_line(&mut first)
        .unwrap();
    let id = first
        .split_whitespace()
        .skip_while(|w| *w != "array")
        .nth(1)
        .unwrap_or_else(|| panic!("no job array id in '{first}'"))
        .to_string();
    (child, id)
}

/// Waits for `child` (scripts/slurm-generate --wait) and returns what it printed after the id.
fn finish(child: std::process::Child) -> String {
    let out = child.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "slurm-generate failed: {text}");
    text
}

/// The unsharded dataset of the same flags, for comparison.
fn unsharded(name: &str, spp: &str) -> PathBuf {
    let dir = fresh_dir(name);
    let mut args = vec!["generate".to_string()];
    args.extend(flags(&dir, spp));
    ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    dir
}

/// SHARDS is refused before anything is submitted where it is no number, zero, or beyond
/// Slurm's largest array, 20 digits included (bash's arithmetic wraps past 64 bits); no
/// cluster needed.
#[test]
fn shard_counts_slurm_cannot_run_are_refused_by_name() {
    for shards in ["0", "-3", "4x", "4000002", "99999999999999999999"] {
        let out = common::script(
            "scripts/slurm-generate",
            &[shards, "--", "--out", "/nonexistent"],
        );
        assert_eq!(out.status.code(), Some(2), "{shards}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(&format!("SHARDS must be a whole number from 1 to 4000001 (Slurm's largest job array), got '{shards}'")),
            "{shards}: {err}"
        );
    }
}

#[test]
fn a_four_task_array_makes_the_unsharded_dataset() {
    if !slurm_runs() {
        return;
    }
    let reference = unsharded("slurm-one", "4");
    let out = fresh_dir("slurm-array");
    let (child, _) = submit("4", &out, "4");
    let text = finish(child);
    assert!(text.contains("12 of 12 views complete"), "{text}");
    assert!(
        views(&out) == views(&reference),
        "views differ from the unsharded run"
    );
    assert_eq!(
        std::fs::read(out.join("manifest.json")).unwrap(),
        std::fs::read(reference.join("manifest.json")).unwrap()
    );
    for k in 0..4 {
        let logs = std::fs::read_dir(out.join("slurm")).unwrap();
        let log = logs
            .map(|e| e.unwrap().path())
            .find(|p| p.to_string_lossy().ends_with(&format!("_{k}.log")))
            .unwrap();
        let log = std::fs::read_to_string(log).unwrap();
        assert!(log.contains(&format!("shard {k}/4")), "{log}");
    }
    std::fs::remove_dir_all(&out).unwrap();
    std::fs::remove_dir_all(&reference).unwrap();
}

/// The process id and array task of a running `nprt generate` writing into `out`.
fn running_task(out: &Path) -> Option<(i32, String)> {
    let out = out.to_str().unwrap();
    for entry in std::fs::read_dir("/proc").ok()?.flatten() {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<i32>() else {
            continue;
        };
        let Ok(cmdline) = std::fs::read(entry.path().join("cmdline")) else {
            continue;
        };
        let args: Vec<String> = cmdline
            .split(|b| *b == 0)
            .map(|a| String::from_utf8_lossy(a).into_owned())
            .collect();
        let is_nprt = args.first().is_some_and(|a| a.ends_with("/nprt"));
        if is_nprt && args.iter().any(|a| a == "generate") && args.iter().any(|a| a == out) {
            let environ = std::fs::read(entry.path().join("environ")).unwrap_or_default();
            let task = environ
                .split(|b| *b == 0)
                .filter_map(|v| std::str::from_utf8(v).ok())
                .find_map(|v| v.strip_prefix("SLURM_ARRAY_TASK_ID="))?
                .to_string();
            return Some((pid, task));
        }
    }
    None
}

/// How many views of shard `k` of `n` are complete on disk in the dataset `out`.
fn shard_views_on_disk(out: &Path, k: u64, n: u64) -> usize {
    let Ok(bytes) = std::fs::read(out.join("manifest.json")) else {
        return 0;
    };
    let manifest: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
    manifest["views"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["index"].as_u64().unwrap() % n == k)
        .filter(|v| out.join(v["file"].as_str().unwrap()).exists())
        .count()
}

fn squeue(args: &[&str]) -> String {
    let o = Command::new("squeue").args(args).output().unwrap();
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn a_task_killed_mid_shard_is_requeued_and_nothing_is_lost() {
    if !slurm_runs() {
        return;
    }
    let spp = "512";
    let reference = unsharded("slurm-kill-one", spp);
    let out = fresh_dir("slurm-kill");
    let (child, array) = submit("2", &out, spp);
    // Kill a task once its own shard has a view on disk and more to do.
    let start = Instant::now();
    let (pid, task) = loop {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no task finished a view"
        );
        if let Some((pid, task)) = running_task(&out) {
            if shard_views_on_disk(&out, task.parse().unwrap(), 2) > 0 {
                break (pid, task);
            }
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let killed = Command::new("kill")
        .args(["-9", &pid.to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    // Slurm holds a requeued job back for two minutes; the test lets it go at once.
    let job = format!("{array}_{task}");
    while !squeue(&["-h", "-t", "PENDING", "-j", &array, "-o", "%i"]).contains(&job) {
        assert!(
            start.elapsed() < Duration::from_secs(150),
            "task {job} was not requeued"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    let released = Command::new("scontrol")
        .args(["update", &format!("JobId={job}"), "StartTime=now"])
        .status()
        .unwrap();
    assert!(released.success());
    let text = finish(child);
    assert!(text.contains("12 of 12 views complete"), "{text}");
    assert!(
        views(&out) == views(&reference),
        "views differ from the unsharded run"
    );
    let log = std::fs::read_to_string(out.join(format!("slurm/generate-{job}.log"))).unwrap();
    assert!(
        log.contains("killed by signal 9; requeueing") && log.contains("run 2"),
        "{log}"
    );
    // The second run kept what the first had finished.
    let kept: u32 = log
        .lines()
        .rev()
        .find_map(|l| l.strip_suffix(" already complete"))
        .and_then(|l| l.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no resume line in {log}"));
    assert!(kept >= 1, "{log}");
    std::fs::remove_dir_all(&out).unwrap();
    std::fs::remove_dir_all(&reference).unwrap();
}
