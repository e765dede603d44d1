//! What a lighting change leaves as it is of a design's tracks on the CPU engine: for a still
//! camera's rows, everything each track computes before the light enters (ŝ behind a transfer
//! network, or a linear track's transfer coefficients), kept and read back by every lighting.

use rayon::prelude::*;

use super::{with_passes, Lighting, StepInput, BLOCK};
use crate::cpu::dense::Pass;
use crate::encoding::features::FEATURES;
use crate::network::nprt_net::NprtNet;
use crate::network::track::Track;

/// What a lighting change leaves as it is of each track, for a set of rows such as a still
/// camera's pixels: everything before the light enters ([`Track::kept_width`] values a row).
pub struct KeptRows {
    pub(super) tracks: Vec<Vec<f32>>,
}

impl Track {
    /// Values per row a still camera keeps of this track: the outputs of its plan's steps
    /// before the light enters (Φ's where it enters at the combine, ŝ where it enters Φ behind
    /// a transfer network), none where the first network reads the code (the baseline).
    pub fn kept_width(&self) -> usize {
        self.plan().kept_width()
    }

    /// What a still camera keeps of the rows of `features`, into `out` (`rows ×`
    /// [`Self::kept_width`]): the plan's steps run up to where the light enters.
    fn kept_block(&self, features: &[f32], out: &mut [f32]) {
        let plan = self.plan();
        // No step before the light reads a code.
        let unlit = Lighting {
            codes: &[],
            view: &[],
        };
        with_passes(1, |passes| {
            let pass = &mut passes[0];
            let input = StepInput::Features(features);
            self.run_steps(&plan, 0..plan.kept, input, unlit, pass, Pass::Infer);
            out.copy_from_slice(pass.tapes[plan.kept - 1].output());
        })
    }
}

impl NprtNet {
    /// What a lighting change leaves as it is of each track for the rows of `features`: ŝ,
    /// or a linear track's Φ outputs (nothing for the baseline, whose every layer sees the
    /// light code).
    pub fn kept_rows(&self, features: &[f32]) -> KeptRows {
        let n = features.len() / FEATURES;
        // Written in place: collected block by block, the codes of a 512² frame (67 MB a
        // track) were copied as the vector grew, into freshly mapped pages each time.
        let tracks = self
            .tracks
            .iter()
            .map(|t| {
                let width = t.kept_width();
                let mut kept = vec![0.0; n * width];
                if width > 0 {
                    kept.par_chunks_mut(BLOCK * width)
                        .zip(features.par_chunks(BLOCK * FEATURES))
                        .for_each(|(out, f)| t.kept_block(f, out));
                }
                kept
            })
            .collect();
        KeptRows { tracks }
    }
}
