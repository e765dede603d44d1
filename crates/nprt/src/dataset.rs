//! `nprt dataset`: inspecting a dataset folder.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

#[derive(clap::Subcommand)]
pub enum DatasetCommand {
    /// Report completeness and problems of a dataset folder; exits 1 unless complete.
    Verify {
        /// Dataset folder (holding manifest.json).
        dir: PathBuf,
    },
}

pub fn run(c: DatasetCommand) -> Result<()> {
    match c {
        DatasetCommand::Verify { dir } => verify(&dir),
    }
}

fn verify(dir: &Path) -> Result<()> {
    let r = nprt_data::dataset::verify(dir)?;
    for f in &r.corrupt {
        println!("corrupt: {f}");
    }
    for f in r.missing.iter().take(20) {
        println!("missing: {f}");
    }
    if r.missing.len() > 20 {
        println!("missing: … and {} more", r.missing.len() - 20);
    }
    for f in &r.leftovers {
        println!("leftover: {f} (a temporary file of a killed or running generate; a re-run of its shard removes it)");
    }
    println!(
        "{}: {} of {} views complete, {} missing, {} corrupt",
        dir.display(),
        r.complete,
        r.views,
        r.missing.len(),
        r.corrupt.len()
    );
    if r.complete != r.views {
        bail!("dataset '{}' is incomplete", dir.display());
    }
    Ok(())
}
