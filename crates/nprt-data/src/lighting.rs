//! The lighting of a dataset: which environment maps, and their split into training maps and
//! held-out test maps (test maps are never seen in training, as in the paper).

use std::path::Path;

use anyhow::{bail, Context, Result};
use nprt_scene::open_envmap;
use nprt_scene::EnvMap;

use crate::dataset::MapAssignment;
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// The share of a folder-lit dataset's training views lit by a procedural lighting of their
/// own unless asked otherwise: half mixed improved every error on held-out real maps against
/// none (docs/evaluation.md, "Held-out real maps: level and tint").
pub const DEFAULT_MIX_BUILTIN: f32 = 0.5;

/// The maps of a dataset and how its views take them, from `--envmaps`: `builtin` draws one
/// fresh procedural lighting per view ([`builtin_per_view`]); a folder's maps form a pool
/// with `test_maps` of them (default: a fifth) held out for testing, and `builtin_share` of
/// the training views (drawn by [`takes_builtin`]) take a fresh procedural lighting of their
/// own instead, listed after the folder's maps, so a few real maps are mixed with many
/// lightings while the test views keep the held-out real ones.
pub fn choose(
    envmaps: &str,
    train_views: u64,
    test_views: u64,
    test_maps: Option<usize>,
    builtin_share: f32,
    seed: u64,
) -> Result<(Vec<String>, MapAssignment)> {
    if train_views == 0 || test_views == 0 {
        bail!(
            "a dataset needs at least one training and one test view (the test views are the references validation and `nprt eval` measure against); got {train_views} and {test_views}"
        );
    }
    if envmaps == "builtin" {
        if test_maps.is_some() {
            bail!("--test-maps applies to a folder of maps; --envmaps builtin gives every view its own lighting");
        }
        if builtin_share > 0.0 {
            bail!("--mix-builtin applies to a folder of maps; --envmaps builtin already gives every view its own built-in lighting");
        }
        return Ok((
            builtin_per_view(train_views, test_views, seed),
            MapAssignment::PerView,
        ));
    }
    if !(0.0..=1.0).contains(&builtin_share) {
        bail!(
            "--mix-builtin is a share of the training views, between 0 and 1; got {builtin_share}"
        );
    }
    let mut specs = specs_in_dir(Path::new(envmaps))?;
    let test_maps = test_maps.unwrap_or_else(|| default_test_count(specs.len()));
    // Whether the folder can hold them out, asked now: the split itself is drawn when planning.
    split(specs.len(), test_maps, seed)?;
    specs.extend(builtin_per_view(
        mixed_views(seed, train_views, builtin_share) as u64,
        0,
        seed,
    ));
    Ok((
        specs,
        MapAssignment::Pool {
            test_maps,
            builtin_share,
        },
    ))
}

/// Whether training view `index` of a folder-lit dataset takes its own built-in lighting: a
/// draw of its own (seeded by `seed` and `index`), so the other views' cameras, maps and
/// rotations are those of the same dataset without mixing.
pub fn takes_builtin(seed: u64, index: u64, builtin_share: f32) -> bool {
    builtin_share > 0.0
        && Pcg64Mcg::seed_from_u64(seed ^ 0x6d18_b017_7e00 ^ index.wrapping_mul(0x9e37_79b9))
            .random::<f32>()
            < builtin_share
}

/// How many of `train_views` training views [`takes_builtin`] picks: the built-in maps a
/// mixed dataset lists after its folder's.
pub fn mixed_views(seed: u64, train_views: u64, builtin_share: f32) -> usize {
    (0..train_views)
        .filter(|&i| takes_builtin(seed, i, builtin_share))
        .count()
}

/// One built-in lighting per view, drawn from `seed`, training views first: two in three are
/// skies (sun elevation 3–70°, azimuth 0–360°, turbidity 2–6), the others indoor layouts.
/// Test lightings never repeat a training one: sky parameters are drawn from continuous
/// ranges, and indoor layouts from even seeds for training and odd ones for testing.
pub fn builtin_per_view(train_views: u64, test_views: u64, seed: u64) -> Vec<String> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x11d1_5ca9_e000);
    (0..train_views + test_views)
        .map(|i| {
            if rng.random::<f32>() < 2.0 / 3.0 {
                let elevation = rng.random_range(3.0..70.0f32);
                let azimuth = rng.random_range(0.0..360.0f32);
                let turbidity = rng.random_range(2.0..6.0f32);
                format!("builtin:sky:{elevation:.3}:{azimuth:.3}:{turbidity:.3}")
            } else {
                // Seeds stay below 2^21, exact in the spec's f32.
                let layout = rng.random_range(0..1u64 << 20) * 2 + u64::from(i >= train_views);
                format!("builtin:indoor:{layout}")
            }
        })
        .collect()
}

/// The .exr and .hdr files of `dir`, sorted by name.
pub fn specs_in_dir(dir: &Path) -> Result<Vec<String>> {
    if dir.is_file() {
        bail!(
            "'{}' is one map; the maps of a dataset are a folder of .exr or .hdr files (at least \
             two: some light only the test views), or builtin",
            dir.display()
        );
    }
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
            &nprt_io::read_input(std::path::Path::new(spec))
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
    fn builtin_lighting_is_one_fresh_map_per_view_and_seeded() {
        let specs = builtin_per_view(300, 40, 5);
        assert_eq!(specs.len(), 340);
        assert_eq!(specs, builtin_per_view(300, 40, 5));
        assert_ne!(specs, builtin_per_view(300, 40, 6));
        let (train, test) = specs.split_at(300);
        assert!(
            test.iter().all(|t| !train.contains(t)),
            "a test lighting repeats a training one"
        );
        let indoor_parity = |s: &[String]| -> Vec<u64> {
            s.iter()
                .filter_map(|x| x.strip_prefix("builtin:indoor:"))
                .map(|n| n.parse::<u64>().unwrap() % 2)
                .collect()
        };
        assert!(indoor_parity(train).iter().all(|&p| p == 0));
        assert!(indoor_parity(test).iter().all(|&p| p == 1));
        let skies = specs
            .iter()
            .filter(|s| s.starts_with("builtin:sky:"))
            .count();
        assert!((200..260).contains(&skies), "{skies} skies of 340");
        assert!(load_all(&specs[..6]).is_ok());
        let (specs, how) = choose("builtin", 3, 2, None, 0.0, 0).unwrap();
        assert_eq!((specs.len(), how), (5, MapAssignment::PerView));
        assert!(choose("builtin", 3, 2, Some(1), 0.0, 0).is_err());
        assert!(choose("builtin", 3, 2, None, 0.5, 0).is_err());
    }

    #[test]
    fn folders_without_maps_are_refused() {
        let dir = std::env::temp_dir().join(format!("nprt-nomaps-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("readme.txt"), "x").unwrap();
        let err = specs_in_dir(&dir).unwrap_err().to_string();
        assert!(err.contains("no .exr or .hdr"), "{err}");
        assert!(specs_in_dir(&dir.join("missing")).is_err());
    }
}
