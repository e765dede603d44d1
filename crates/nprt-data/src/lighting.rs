//! The lighting of a dataset: which environment maps, and their split into training maps and
//! held-out test maps (test maps are never seen in training, as in the paper).

use std::path::Path;

use anyhow::{bail, Context, Result};
use nprt_scene::open_envmap;
use nprt_scene::EnvMap;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

/// Built-in maps for when no files are given: 16 skies (4 sun elevations × 4 azimuths,
/// turbidity 2–5) and 8 indoor maps.
pub fn builtin_specs() -> Vec<String> {
    let mut specs = vec![];
    for (i, elevation) in [8.0, 20.0, 40.0, 65.0].iter().enumerate() {
        for (j, azimuth) in [20.0, 110.0, 200.0, 290.0].iter().enumerate() {
            let turbidity = 2.0 + ((i + j) % 4) as f32;
            specs.push(format!("builtin:sky:{elevation}:{azimuth}:{turbidity}"));
        }
    }
    specs.extend((0..8).map(|s| format!("builtin:indoor:{s}")));
    specs
}

/// The .exr and .hdr files of `dir`, sorted by name.
pub fn specs_in_dir(dir: &Path) -> Result<Vec<String>> {
    let entries = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read environment map folder '{}'", dir.display()))?;
    let mut specs = vec![];
    for e in entries {
        let path = e
            .with_context(|| format!("cannot list '{}'", dir.display()))?
            .path();
        let ext = path
            .extension()
            .and_then(|x| x.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        if ext == "exr" || ext == "hdr" {
            specs.push(path.to_string_lossy().into_owned());
        }
    }
    specs.sort();
    if specs.is_empty() {
        bail!(
            "environment map folder '{}' holds no .exr or .hdr files",
            dir.display()
        );
    }
    Ok(specs)
}

/// Loads every map (so a bad one stops the run before any rendering).
pub fn load_all(specs: &[String]) -> Result<Vec<EnvMap>> {
    specs.iter().map(|s| open_envmap(s)).collect()
}

/// Identity of a map spec: BLAKE3 of the file's bytes, or of the spec for a built-in map.
pub fn map_hash(spec: &str) -> Result<String> {
    let hash = if spec.starts_with("builtin:") {
        blake3::hash(spec.as_bytes())
    } else {
        blake3::hash(
            &std::fs::read(spec)
                .with_context(|| format!("cannot read environment map '{spec}'"))?,
        )
    };
    Ok(hash.to_hex().to_string())
}

/// Draws `test_count` held-out maps with `seed`: (train indices, test indices), each sorted.
pub fn split(count: usize, test_count: usize, seed: u64) -> Result<(Vec<usize>, Vec<usize>)> {
    if count < 2 {
        bail!("a dataset needs at least 2 environment maps (one to train, one held out for testing); got {count}");
    }
    if test_count == 0 || test_count >= count {
        bail!(
            "--test-maps must be between 1 and {} for {count} maps; got {test_count}",
            count - 1
        );
    }
    let mut order: Vec<usize> = (0..count).collect();
    order.shuffle(&mut Pcg64Mcg::seed_from_u64(seed ^ 0x5eed_1161));
    let (mut test, mut train) = (order[..test_count].to_vec(), order[test_count..].to_vec());
    test.sort();
    train.sort();
    Ok((train, test))
}

/// The paper holds out about a fifth of the maps.
pub fn default_test_count(count: usize) -> usize {
    count.div_ceil(5).clamp(1, count.saturating_sub(1).max(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_is_disjoint_complete_and_seeded() {
        let (train, test) = split(13, 3, 1).unwrap();
        assert_eq!(test.len(), 3);
        assert_eq!(train.len(), 10);
        let mut all: Vec<_> = train.iter().chain(&test).copied().collect();
        all.sort();
        assert_eq!(all, (0..13).collect::<Vec<_>>());
        assert_eq!(split(13, 3, 1).unwrap(), (train.clone(), test.clone()));
        assert_ne!(split(13, 3, 2).unwrap().1, test);
        assert!(split(1, 1, 0)
            .unwrap_err()
            .to_string()
            .contains("at least 2"));
        assert!(split(4, 4, 0).is_err());
        assert_eq!(default_test_count(13), 3);
        assert_eq!(default_test_count(2), 1);
    }

    #[test]
    fn folders_without_maps_are_refused() {
        let dir = std::env::temp_dir().join(format!("nprt-nomaps-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("readme.txt"), "x").unwrap();
        let err = specs_in_dir(&dir).unwrap_err().to_string();
        assert!(err.contains("no .exr or .hdr"), "{err}");
        assert!(specs_in_dir(&dir.join("missing")).is_err());
        assert_eq!(builtin_specs().len(), 24);
    }
}
