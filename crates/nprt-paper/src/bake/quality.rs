//! `nprt bake --quality`: how big a baked model's dataset, training and check are, stated once
//! here, and how the dataset grows with the scene.

use std::fmt;
use std::str::FromStr;

use anyhow::{bail, Result};
use glam::Vec3;
use nprt_scene::CameraVolume;

/// A bake's sizes: draft (minutes on a laptop's CPU), good, or best; tiny for tests only.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quality {
    /// Test-only sizes: end to end in seconds, deciding nothing.
    Tiny,
    Draft,
    Good,
    Best,
}

/// Everything a quality sets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sizes {
    /// Training views for a camera volume spanning up to [`BASE_SPAN`] of the scene (more for
    /// a wider one: [`Quality::sizes_for`]).
    pub train_views: u64,
    pub train_res: u32,
    /// Samples per pixel of the training views: cleaner targets changed nothing measurable at
    /// minutes of training (docs/model.md), so the draft takes fewer.
    pub spp: u32,
    /// Held-out views the bake checks its model on, with their references' samples.
    pub test_views: u64,
    pub test_res: u32,
    pub test_spp: u32,
    /// Training, wall-clock minutes (`--minutes` replaces it).
    pub minutes: f64,
    /// Minutes of training after which a first relit frame is written (preview.png).
    pub preview_minutes: f64,
    /// Paths per pixel of the SH PRT baseline in the check.
    pub sh_spp: u32,
}

/// The share of the scene's diagonal a camera volume's diagonal may span before a bake renders
/// more views: builtin:room's volume spans 0.61 of its box.
pub const BASE_SPAN: f32 = 0.65;

/// The most a wide camera volume multiplies the training views by.
pub const MAX_VIEW_SCALE: f32 = 3.0;

impl Quality {
    pub const ALL: [Quality; 4] = [Quality::Tiny, Quality::Draft, Quality::Good, Quality::Best];

    pub fn name(self) -> &'static str {
        match self {
            Quality::Tiny => "tiny",
            Quality::Draft => "draft",
            Quality::Good => "good",
            Quality::Best => "best",
        }
    }

    /// The sizes for a scene of average span: builtin:room at `draft` takes under 10 minutes on
    /// 2 cores (docs/model.md, "nprt bake").
    pub fn sizes(self) -> Sizes {
        match self {
            Quality::Tiny => Sizes {
                train_views: 12,
                train_res: 24,
                spp: 8,
                test_views: 2,
                test_res: 24,
                test_spp: 16,
                minutes: 0.25,
                preview_minutes: 0.02,
                sh_spp: 4,
            },
            Quality::Draft => Sizes {
                train_views: 150,
                train_res: 64,
                spp: 32,
                test_views: 8,
                test_res: 64,
                test_spp: 256,
                minutes: 4.0,
                preview_minutes: 0.5,
                sh_spp: 32,
            },
            Quality::Good => Sizes {
                train_views: 400,
                train_res: 64,
                spp: 64,
                test_views: 16,
                test_res: 96,
                test_spp: 512,
                minutes: 12.0,
                preview_minutes: 1.0,
                sh_spp: 64,
            },
            Quality::Best => Sizes {
                train_views: 1000,
                train_res: 96,
                spp: 128,
                test_views: 32,
                test_res: 128,
                test_spp: 1024,
                minutes: 40.0,
                preview_minutes: 2.0,
                sh_spp: 256,
            },
        }
    }

    /// The sizes for a scene whose bounds are `bounds` (min, max) and whose cameras move in
    /// `volume`: the training views grow with the share of the scene the cameras roam (the
    /// volume's diagonal over the scene's, beyond [`BASE_SPAN`]), up to [`MAX_VIEW_SCALE`]
    /// times, so that a wide walk-through sees each surface from as many places as a small one.
    pub fn sizes_for(self, bounds: (Vec3, Vec3), volume: &CameraVolume) -> Sizes {
        let base = self.sizes();
        let scene = (bounds.1 - bounds.0).length();
        let span = (volume.max - volume.min).length() / scene.max(f32::MIN_POSITIVE);
        let scale = (span / BASE_SPAN).clamp(1.0, MAX_VIEW_SCALE);
        Sizes {
            train_views: (base.train_views as f32 * scale).round() as u64,
            ..base
        }
    }
}

impl FromStr for Quality {
    type Err = anyhow::Error;

    fn from_str(s: &str) -> Result<Quality> {
        match Quality::ALL.into_iter().find(|q| q.name() == s) {
            Some(q) => Ok(q),
            None => bail!("unknown quality '{s}': choose draft, good or best (or tiny, for tests)"),
        }
    }
}

impl fmt::Display for Quality {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn volume(min: Vec3, max: Vec3) -> CameraVolume {
        CameraVolume {
            min,
            max,
            look: Vec3::NEG_Z,
            spread_deg: 30.0,
            fov_deg: 60.0,
        }
    }

    #[test]
    fn qualities_grow_and_a_wide_camera_volume_gets_more_views() {
        for q in Quality::ALL {
            assert_eq!(q.name().parse::<Quality>().unwrap(), q);
        }
        assert!("fine"
            .parse::<Quality>()
            .unwrap_err()
            .to_string()
            .contains("draft, good or best"));
        let cost = |s: Sizes| s.train_views * u64::from(s.train_res.pow(2) * s.spp);
        for w in Quality::ALL.windows(2) {
            let (a, b) = (w[0].sizes(), w[1].sizes());
            assert!(cost(a) < cost(b) && a.minutes < b.minutes && a.test_views < b.test_views);
        }
        let scene = (Vec3::splat(-5.0), Vec3::splat(5.0));
        let draft = Quality::Draft.sizes();
        // builtin:room's volume within its box: the base count.
        let room = Quality::Draft.sizes_for(
            (Vec3::new(-3.0, 0.0, -3.0), Vec3::new(3.0, 3.0, 3.0)),
            &volume(Vec3::new(-2.2, 0.9, -0.2), Vec3::new(2.2, 2.2, 2.8)),
        );
        assert_eq!(room, draft);
        // A volume spanning 0.78 of the scene: more views, in proportion; the whole scene
        // likewise; a volume reaching far beyond it, at most 3×.
        let wide = Quality::Draft.sizes_for(scene, &volume(Vec3::splat(-3.9), Vec3::splat(3.9)));
        assert_eq!(
            wide.train_views,
            (150.0f32 * 0.78 / BASE_SPAN).round() as u64
        );
        let whole = Quality::Draft.sizes_for(scene, &volume(scene.0, scene.1));
        assert_eq!(whole.train_views, (150.0f32 / BASE_SPAN).round() as u64);
        let beyond = Quality::Draft.sizes_for(scene, &volume(scene.0 * 3.0, scene.1 * 3.0));
        assert_eq!(beyond.train_views, 450);
        // Only the views change.
        assert_eq!(
            Sizes {
                train_views: draft.train_views,
                ..whole
            },
            draft
        );
    }
}
