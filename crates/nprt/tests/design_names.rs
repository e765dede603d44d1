//! Lists of designs outside the code follow `Design::ALL`: the commands' help (clap's possible
//! values, from it), and the PyTorch peer's table, whose designs must be nprt's (a design added
//! to nprt needs no PyTorch twin to pass).

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
        assert!(
            help.contains(&want),
            "nprt {command:?} --help lacks {want}: {help}"
        );
    }
}

/// The PyTorch peer has a twin of some designs (the paper's four): each under nprt's name, and
/// its default runs them all.
#[test]
fn the_pytorch_peers_designs_are_nprts() {
    let peer = repository_file("bench/train_pytorch.py");
    let start = peer
        .find("TRACKS = {")
        .expect("train_pytorch.py's TRACKS table");
    let table = &peer[start..start + peer[start..].find('}').unwrap()];
    // Each key is the last quoted word before `": [`.
    let pieces: Vec<&str> = table.split("\": [").collect();
    let twins: Vec<&str> = pieces[..pieces.len() - 1]
        .iter()
        .filter_map(|piece| piece.rsplit('"').next())
        .collect();
    for name in Design::PAPER.map(Design::name) {
        assert!(twins.contains(&name), "the peer lacks {name}: {twins:?}");
    }
    for twin in twins {
        assert!(
            twin.parse::<Design>().is_ok(),
            "the peer's design {twin} is not nprt's"
        );
    }
    assert!(peer.contains("default=\",\".join(TRACKS)"));
}
