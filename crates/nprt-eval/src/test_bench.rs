//! What every method is evaluated on: the dataset's test views with their maps, the scene to
//! trace, the views whose images the report shows, and the evaluation's progress bar.

use std::collections::BTreeMap;

use glam::Vec3;
use indicatif::ProgressBar;
use nprt_data::dataset::Settings;
use nprt_data::views::ImageView;
use nprt_scene::EnvMap;
use nprt_trace::{PixelFilter, RenderSettings, TraceScene};

use crate::shown_view::ShownView;

pub struct TestBench<'a> {
    pub views: &'a [ImageView],
    /// The maps the views name, by their index in the dataset's manifest.
    pub maps: &'a BTreeMap<usize, EnvMap>,
    pub ts: &'a TraceScene<'a>,
    /// The dataset's integrator settings (max_depth, Russian roulette).
    pub settings: &'a Settings,
    /// Salt of every baseline's random seeds.
    pub seed: u64,
    /// Samples per pixel of the direct light that models trained to leave it to the tracer add.
    pub direct_spp: u32,
    pub shown: Vec<ShownView>,
    pub bar: ProgressBar,
}

impl TestBench<'_> {
    /// The map view `v` names, as the dataset records it.
    pub fn map(&self, v: &ImageView) -> &EnvMap {
        &self.maps[&v.record.map]
    }

    /// The map lighting view `v`, rotated as recorded.
    pub fn lighting(&self, v: &ImageView) -> EnvMap {
        self.map(v).rotated_y(v.record.rotation_deg)
    }

    /// The dataset's path tracer at `spp`, every sample through the pixel centre.
    pub fn path_tracer(&self, spp: u32, seed: u64) -> RenderSettings {
        RenderSettings {
            spp,
            max_depth: self.settings.max_depth,
            rr_depth: self.settings.rr_depth,
            seed,
            filter: PixelFilter::Centre,
            progress: false,
        }
    }

    /// Keeps `rgb` as method `name`'s image of test view `k` if the report shows that view.
    pub fn show(&mut self, k: usize, name: &str, rgb: &[Vec3]) {
        if let Some(s) = self.shown.get_mut(k) {
            s.methods.push((name.to_string(), rgb.to_vec()));
        }
    }
}
