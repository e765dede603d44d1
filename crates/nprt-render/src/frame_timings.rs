//! Where a relit frame's time goes, stage by stage.

/// Milliseconds spent in each stage of one frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameTimings {
    pub gbuffer_ms: f64,
    pub encoder_ms: f64,
    pub network_ms: f64,
    /// Traced direct light (models that trace it) or the background.
    pub direct_ms: f64,
}

impl FrameTimings {
    /// Adds `t`'s stages to these.
    pub fn add(&mut self, t: &FrameTimings) {
        self.gbuffer_ms += t.gbuffer_ms;
        self.encoder_ms += t.encoder_ms;
        self.network_ms += t.network_ms;
        self.direct_ms += t.direct_ms;
    }

    /// Every stage times `k` (a mean from a sum).
    pub fn scaled(&self, k: f64) -> FrameTimings {
        FrameTimings {
            gbuffer_ms: self.gbuffer_ms * k,
            encoder_ms: self.encoder_ms * k,
            network_ms: self.network_ms * k,
            direct_ms: self.direct_ms * k,
        }
    }

    /// Each stage's median over `frames` (the upper one of an even count).
    pub fn median(frames: &[FrameTimings]) -> FrameTimings {
        let stage = |f: fn(&FrameTimings) -> f64| nprt_net::median(frames.iter().map(f).collect());
        FrameTimings {
            gbuffer_ms: stage(|t| t.gbuffer_ms),
            encoder_ms: stage(|t| t.encoder_ms),
            network_ms: stage(|t| t.network_ms),
            direct_ms: stage(|t| t.direct_ms),
        }
    }

    pub fn total_ms(&self) -> f64 {
        self.gbuffer_ms + self.encoder_ms + self.network_ms + self.direct_ms
    }
}
