//! Every list of designs written outside the code is `Design::ALL`'s: the commands' help (from
//! clap's possible values), docs/commands.md, the PyTorch peer's table and default, and the GPU
//! benchmark's list. A design added to `Design::ALL` fails here until each list has it.

use std::path::Path;
use std::process::Command;

use nprt_net::Design;

fn names(separator: &str) -> String {
    Design::ALL.map(Design::name).join(separator)
}

fn repository_file(path: &str) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    std::fs::read_to_string(root.join(path)).unwrap_or_else(|e| panic!("{path}: {e}"))
}

#[test]
fn the_commands_help_lists_every_design() {
    for command in [&["train"][..], &["model", "info"], &["bench", "train"]] {
        let out = Command::new(env!("CARGO_BIN_EXE_nprt"))
            .args(command)
            .arg("--help")
            .output()
            .unwrap();
        let help = String::from_utf8_lossy(&out.stdout).replace(char::is_whitespace, "");
        let want = format!("[possiblevalues:{}]", names(","));
        assert!(help.contains(&want), "nprt {command:?} --help lacks {want}: {help}");
    }
}

#[test]
fn written_lists_of_designs_are_design_all() {
    let commands = repository_file("docs/commands.md");
    assert!(commands.contains(&format!("--arch {}", names("|"))));
    let peer = repository_file("bench/train_pytorch.py");
    assert!(peer.contains(&format!("default=\"{}\"", names(","))));
    for name in Design::ALL.map(Design::name) {
        assert!(peer.contains(&format!("\"{name}\": [")), "train_pytorch.py's tracks of {name}");
    }
    let gpu = repository_file("bench/gpu.sh");
    assert!(gpu.contains(&format!("designs={}", names(","))));
    assert!(gpu.contains(&format!("/^({})$/", names("|"))));
}
