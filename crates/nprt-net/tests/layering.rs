//! The layering nprt-net's crate doc and `gpu`'s module doc state, held by its sources: no
//! module imports one of a later layer (outside test modules), and no GPU file reaches the
//! runtime or a sibling through `gpu`'s own re-exports.

use std::path::{Path, PathBuf};

/// The crate's modules by layer (lib.rs: shared pieces, encoding, network, optimiser and model,
/// the engines, training, then Deep Shading and the benchmarks).
const CRATE_LAYERS: &[&[&str]] = &[
    &["precision", "parameters", "init", "loss", "choice"],
    &["encoding"],
    &["network"],
    &["optimiser", "model"],
    &["cpu", "gpu", "shading", "engine"],
    &["training"],
    &["deep_shading", "bench"],
];

/// `gpu`'s folders by layer (gpu/mod.rs).
const GPU_LAYERS: &[&[&str]] = &[
    &["kernels"],
    &["products"],
    &["layers"],
    &["passes"],
    &["trainers", "frame"],
];

fn layer(layers: &[&[&str]], module: &str) -> Option<usize> {
    layers.iter().position(|l| l.contains(&module))
}

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The modules `prefix` names in `code` (`crate::X` for `crate::`), outside test modules.
fn imported<'a>(code: &'a str, prefix: &str) -> Vec<&'a str> {
    let code = code.split("#[cfg(test)]").next().unwrap();
    code.match_indices(prefix)
        .map(|(i, _)| {
            let rest = &code[i + prefix.len()..];
            let end = rest
                .find(|c: char| !(c.is_ascii_lowercase() || c == '_'))
                .unwrap_or(rest.len());
            &rest[..end]
        })
        .collect()
}

#[test]
fn no_module_imports_a_later_layer() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let mut checked = 0;
    for file in files {
        let relative = file.strip_prefix(&src).unwrap();
        let mut parts = relative
            .iter()
            .map(|p| p.to_str().unwrap().trim_end_matches(".rs"));
        let top = parts.next().unwrap();
        if top == "lib" {
            continue;
        }
        let code = std::fs::read_to_string(&file).unwrap();
        let own = layer(CRATE_LAYERS, top).unwrap_or_else(|| panic!("{top} is in no layer"));
        for m in imported(&code, "crate::") {
            let theirs = layer(CRATE_LAYERS, m);
            assert!(
                theirs.is_none_or(|l| l <= own),
                "{}: {top} imports {m}, a later layer",
                relative.display()
            );
            checked += 1;
        }
        if top != "gpu" {
            continue;
        }
        let folder = parts.next().unwrap();
        let Some(own) = layer(GPU_LAYERS, folder) else {
            assert_eq!(
                folder,
                "mod",
                "{} is in no layer of gpu",
                relative.display()
            );
            continue;
        };
        assert!(
            !code.contains("use super::{") && !code.contains("crate::gpu::{"),
            "{}: imports through gpu's re-exports",
            relative.display()
        );
        for m in imported(&code, "crate::gpu::") {
            let theirs = layer(GPU_LAYERS, m).unwrap_or_else(|| panic!("gpu::{m} in no layer"));
            assert!(
                theirs <= own,
                "{}: gpu's {folder} imports {m}, a later layer",
                relative.display()
            );
            checked += 1;
        }
    }
    assert!(checked > 100, "only {checked} imports seen");
}
