//! The options of an evaluation, each default stated once here.

use std::path::PathBuf;

use anyhow::{bail, Result};
use nprt_render::DEFAULT_DIRECT_SPP;
use nprt_trace::TraceDevice;

/// The most frames the warmed radiance caches render before the path: a cache settles in tens.
pub const MAX_NRC_WARMUP: usize = 1_000;

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
    /// Also score each part of a traced design's image with the other part the reference's
    /// (`oracles`): where its error lives.
    pub oracles: bool,
    pub progress: bool,
}

impl EvalOptions {
    /// Refuses options no evaluation can run, before any work: counts of zero, sizes whose
    /// frames the machine cannot hold (the memory check `render` and `generate` make), and a
    /// warm-up without end, and frames past what `device` rasterises. Each message names the
    /// flag.
    pub fn check(&self, device: TraceDevice) -> Result<()> {
        if self.sh_spp == 0 || self.timing_res < 8 {
            bail!("--sh-spp must be at least 1 and --timing-res at least 8");
        }
        if self.max_views == Some(0) {
            bail!("--views must be at least 1 (it limits the test views evaluated)");
        }
        let side = self.timing_res;
        device.check_frame(
            side,
            side,
            &format!("--timing-res {side}: a {side}×{side} frame"),
        )?;
        if self.temporal_frames == 0 {
            return Ok(());
        }
        if self.temporal_frames < 2 || self.temporal_res < 8 {
            bail!("--temporal-frames must be 0 or at least 2, and --temporal-res at least 8");
        }
        let side = self.temporal_res;
        device.check_frame(
            side,
            side,
            &format!("--temporal-res {side}: a {side}×{side} frame"),
        )?;
        // Every method's frames along the path are kept for the report, with the references'
        // two halves and the path-traced rows: 3 f32 a pixel each.
        let rows = 2 * (self.models.len() + 1) + 6;
        let bytes = self.temporal_frames as u128 * rows as u128 * (side as u128).pow(2) * 12;
        let what = format!(
            "--temporal-frames {} at --temporal-res {side}",
            self.temporal_frames
        );
        nprt_io::ensure_memory(bytes, &what)?;
        if self.nrc_warmup > MAX_NRC_WARMUP {
            bail!(
                "--nrc-warmup {} is more than {MAX_NRC_WARMUP} frames (a radiance cache \
                 settles in tens)",
                self.nrc_warmup
            );
        }
        Ok(())
    }
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
            oracles: false,
            progress: true,
        }
    }
}
