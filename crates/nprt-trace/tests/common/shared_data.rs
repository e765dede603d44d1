//! Where the repository and the large optional data beside it are.

use std::path::{Path, PathBuf};

/// The repository's root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

/// The folder of large optional data beside the repository (`NPRT_SHARED`, else `../shared`)
/// when it holds `sub`. Absent, the test is skipped, unless `NPRT_REQUIRE_SHARED=1` (CI) makes
/// that a failure.
pub fn shared(sub: &str) -> Option<PathBuf> {
    let root = std::env::var_os("NPRT_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join("../shared"));
    let path = root.join(sub);
    if path.exists() {
        return Some(path);
    }
    assert!(
        std::env::var("NPRT_REQUIRE_SHARED").as_deref() != Ok("1"),
        "NPRT_REQUIRE_SHARED=1 but {} is missing",
        path.display()
    );
    eprintln!(
        "SKIPPED: {} is absent (set NPRT_SHARED to the shared data folder)",
        path.display()
    );
    None
}
