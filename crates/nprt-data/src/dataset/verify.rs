//! Verifying a dataset folder: every view present, complete and of the planned size.

use std::path::{Path, PathBuf};

use anyhow::Result;

use super::manifest::load_manifest_hashed;
use super::pack_format::PackedTarget;
use super::packed::PackedDataset;
use super::packing::views_stamp;
use super::view_file::check_view;

/// Completeness of a dataset folder.
#[derive(Debug, Default)]
pub struct Report {
    pub views: usize,
    pub complete: usize,
    pub missing: Vec<String>,
    pub corrupt: Vec<String>,
    /// Temporary files of views whose writing was killed (or is under way in a running shard).
    pub leftovers: Vec<String>,
    /// Each pack present and its state (a pack out of date is made again by the next training).
    pub packs: Vec<String>,
}

/// Reads every view back fully (in parallel: this is also how fast a trainer can load them).
pub fn verify(dir: &Path) -> Result<Report> {
    use rayon::prelude::*;
    let (manifest, hash) = load_manifest_hashed(dir)?;
    let states: Vec<Result<(), String>> = manifest
        .views
        .par_iter()
        .map(|v| {
            let path: PathBuf = dir.join(&v.file);
            if !path.exists() {
                return Err(String::new());
            }
            check_view(&path, v, manifest.settings.parts(v)).map_err(|e| format!("{e:#}"))
        })
        .collect();
    let mut report = Report {
        views: manifest.views.len(),
        ..Default::default()
    };
    let folders: std::collections::BTreeSet<PathBuf> = manifest
        .views
        .iter()
        .filter_map(|v| Path::new(&v.file).parent().map(Path::to_path_buf))
        .collect();
    for folder in folders {
        for (tmp, _) in nprt_io::leftover_temporaries(&dir.join(folder))? {
            report.leftovers.push(tmp.display().to_string());
        }
    }
    for target in [PackedTarget::Radiance, PackedTarget::Indirect] {
        let path = PackedDataset::path(dir, target);
        if !path.exists() {
            continue;
        }
        let state = views_stamp(dir, &manifest)
            .and_then(|stamp| PackedDataset::open_current(dir, &manifest, &hash, &stamp, target));
        report.packs.push(match state {
            Ok(p) => format!(
                "{}: current ({} records)",
                path.display(),
                p.records().len()
            ),
            Err(e) => format!(
                "{}: out of date, the next training packs it again ({e:#})",
                path.display()
            ),
        });
    }
    for (v, state) in manifest.views.iter().zip(states) {
        match state {
            Ok(()) => report.complete += 1,
            Err(e) if e.is_empty() => report.missing.push(v.file.clone()),
            Err(e) => report.corrupt.push(format!("{}: {e}", v.file)),
        }
    }
    Ok(report)
}
