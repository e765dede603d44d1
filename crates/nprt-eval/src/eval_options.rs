//! The options of an evaluation, each default stated once here.

use std::path::PathBuf;

use nprt_render::DEFAULT_DIRECT_SPP;

/// What to evaluate; `Default` needs `data` and `models` filled in.
#[derive(Clone, Debug)]
pub struct EvalOptions {
    pub data: PathBuf,
    pub models: Vec<PathBuf>,
    pub deep_shading: Option<PathBuf>,
    /// Paths per pixel of the SH transport precomputation.
    pub sh_spp: u32,
    /// Side of the square frames of the timing table (the paper: 512).
    pub timing_res: u32,
    /// Evaluate only the first N test views.
    pub max_views: Option<usize>,
    /// Test views shown as images in the report.
    pub shown_views: usize,
    pub seed: u64,
    /// Samples per pixel of the direct light of models that trace it.
    pub direct_spp: u32,
    /// Frames of the temporal evaluation along a camera path (0: none).
    pub temporal_frames: usize,
    /// Side of its square frames.
    pub temporal_res: u32,
    /// Frames the warmed radiance caches render before the path's first (0: cold ones only).
    pub nrc_warmup: usize,
    pub progress: bool,
}

impl Default for EvalOptions {
    fn default() -> Self {
        EvalOptions {
            data: PathBuf::new(),
            models: vec![],
            deep_shading: None,
            sh_spp: 256,
            timing_res: 512,
            max_views: None,
            shown_views: 3,
            seed: 0,
            direct_spp: DEFAULT_DIRECT_SPP,
            temporal_frames: 12,
            temporal_res: 64,
            nrc_warmup: 8,
            progress: true,
        }
    }
}
