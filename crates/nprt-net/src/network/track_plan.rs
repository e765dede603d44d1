//! A track's sequence as data: the networks it runs in order, what each one's first layer
//! reads, and the step from which the lighting enters. It is stated once here, from the track's
//! networks and its [`LightEntry`]; the CPU engine's forward and backward, the GPU frame path
//! (what a still camera keeps, what a lighting change runs) and the GPU trainer walk it instead
//! of writing "transfer network, then shading network" themselves. How each step runs (its
//! precision, fused or a layer a dispatch) stays the engine's choice.

use std::ops::Range;

use crate::network::light_entry::LightEntry;

/// One of a track's networks, as its parameters name it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Net {
    /// F_T, on the pixel inputs: ŝ.
    Transfer,
    /// Φ: log-radiance, or a linear track's transfer coefficients.
    Shading,
}

impl Net {
    /// Its name among the track's parameters and in the export.
    pub fn name(self) -> &'static str {
        match self {
            Net::Transfer => "transfer",
            Net::Shading => "shading",
        }
    }
}

/// One network of a track's sequence and what its first layer reads.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Step {
    pub net: Net,
    /// Width of its per-row input: the track's inputs (with the grid's encoding) at the first
    /// step, the previous step's outputs after it.
    pub own_width: usize,
    /// The first weight row multiplying that input.
    pub own_row: usize,
    /// The first layer's rows multiplying the light code, where this network reads it.
    pub code_rows: Option<Range<usize>>,
    /// Its outputs per row.
    pub outputs: usize,
}

/// A track's networks in the order they run. The light enters the last step's first layer, or
/// after every step (at the combine): a lighting change runs one network at most.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TrackPlan {
    pub steps: Vec<Step>,
    /// How many steps run before the light enters: what a still camera keeps is the last of
    /// their outputs. All of them where the light enters at the combine.
    pub kept: usize,
}

impl TrackPlan {
    /// The plan of a track reading `width` values a row, with a transfer network of
    /// `transfer` outputs where it has one, a shading network of `outputs` outputs, and its
    /// light entering as `light`.
    pub fn new(width: usize, transfer: Option<usize>, outputs: usize, light: LightEntry) -> Self {
        let mut steps = Vec::with_capacity(2);
        if let Some(s) = transfer {
            steps.push(Step {
                net: Net::Transfer,
                own_width: width,
                own_row: 0,
                code_rows: None,
                outputs: s,
            });
        }
        steps.push(Step {
            net: Net::Shading,
            own_width: transfer.unwrap_or(width),
            own_row: light.own_row(),
            code_rows: light.code_rows(),
            outputs,
        });
        let kept = (steps.iter())
            .position(|s| s.code_rows.is_some())
            .unwrap_or(steps.len());
        debug_assert!(kept + 1 >= steps.len(), "the light enters the last step");
        TrackPlan { steps, kept }
    }

    /// The steps a still camera runs once: before the light enters.
    pub fn unlit(&self) -> &[Step] {
        &self.steps[..self.kept]
    }

    /// The step the light enters, which a lighting change runs; None where it enters at the
    /// combine.
    pub fn lit(&self) -> Option<&Step> {
        self.steps.get(self.kept)
    }

    /// Values per row a still camera keeps: the outputs of the last step before the light
    /// enters; 0 where the first step reads the light (the engine may keep its inputs).
    pub fn kept_width(&self) -> usize {
        self.unlit().last().map_or(0, |s| s.outputs)
    }

    /// The last step: its outputs make the track's radiance at the combine.
    pub fn last(&self) -> &Step {
        self.steps.last().expect("a track has a shading network")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's tracks keep ŝ (the light enters Φ), the baseline keeps nothing (its only
    /// network reads the code), a linear track keeps Φ's outputs (the light enters after it).
    #[test]
    fn a_still_camera_keeps_what_runs_before_the_light() {
        let dsep = TrackPlan::new(9, Some(64), 3, LightEntry::first_layer(Some(64), 64));
        assert_eq!((dsep.kept, dsep.kept_width()), (1, 64));
        assert_eq!(dsep.lit(), Some(dsep.last()));
        assert_eq!(dsep.steps[1].own_width, 64);
        assert_eq!(dsep.steps[1].code_rows, Some(64..128));
        let baseline = TrackPlan::new(19, None, 3, LightEntry::first_layer(None, 64));
        assert_eq!((baseline.kept, baseline.kept_width()), (0, 0));
        assert_eq!((baseline.steps[0].own_row, baseline.steps[0].own_width), (64, 19));
        let linear = TrackPlan::new(9, Some(64), 75, LightEntry::Combine { k: 25 });
        assert_eq!((linear.kept, linear.kept_width()), (2, 75));
        assert_eq!((linear.last().net, linear.lit()), (Net::Shading, None));
    }
}
