//! `nprt dataset`: inspecting a dataset folder and packing it for training.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use nprt_data::dataset::{load_manifest_hashed, PackedDataset};
use nprt_net::DirectLight;

#[derive(clap::Subcommand)]
pub enum DatasetCommand {
    /// Report completeness and problems of a dataset folder; exits 1 unless complete.
    Verify {
        /// Dataset folder (holding manifest.json).
        dir: PathBuf,
    },
    /// Pack a dataset for training (`nprt train` does it at first use): every foreground pixel
    /// as a 40-byte record in one file beside manifest.json (docs/dataset.md), memory-mapped so
    /// that a set larger than memory trains. Nothing is done where the pack is current.
    Pack {
        /// Dataset folder (holding manifest.json).
        dir: PathBuf,
        /// What the records' radiance holds: all of it (learned, for models that learn the
        /// direct light) or the indirect part (traced).
        #[arg(long, default_value_t = DirectLight::Learned)]
        direct: DirectLight,
    },
}

pub fn run(c: DatasetCommand) -> Result<()> {
    match c {
        DatasetCommand::Verify { dir } => verify(&dir),
        DatasetCommand::Pack { dir, direct } => pack(&dir, direct),
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
    for p in &r.packs {
        println!("pack: {p}");
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

fn pack(dir: &Path, direct: DirectLight) -> Result<()> {
    let (manifest, hash) = load_manifest_hashed(dir)?;
    let t0 = std::time::Instant::now();
    let pack =
        PackedDataset::open_or_pack(dir, &manifest, &hash, direct.packed_target(), true, |why| {
            eprintln!("{why}")
        })?;
    println!(
        "'{}': {} records of {} views, {:.2} GB ({:.1} s)",
        PackedDataset::path(dir, direct.packed_target()).display(),
        pack.records().len(),
        manifest.views.len(),
        pack.bytes() as f64 / 1e9,
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
