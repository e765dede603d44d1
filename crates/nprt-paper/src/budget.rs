//! The sizes an experiment runs at, stated once: `nprt paper --budget` and `nprt demo` read them
//! here, and docs/paper.md gives each one's measured (or projected) wall time.

use std::fmt;
use std::str::FromStr;

use anyhow::{bail, Result};
use nprt_net::{LrSchedule, RunLength};

/// Every size of one run of the pipeline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    pub name: &'static str,
    pub train_views: u64,
    pub test_views: u64,
    pub train_res: u32,
    pub test_res: u32,
    /// Samples per pixel of the training views.
    pub spp: u32,
    /// Samples per pixel of the test views: the references.
    pub test_spp: u32,
    /// Each Neural PRT network's training (Table 5's designs and Table 2's ablation alike).
    pub training: RunLength,
    pub deep_shading: RunLength,
    /// Paths per pixel of SH PRT's transport.
    pub sh_spp: u32,
    /// Side of the timing table's frames (the paper: 512).
    pub timing_res: u32,
    /// Frames of the temporal evaluation and their side.
    pub temporal: (usize, u32),
    /// Frames of the relit camera path and their side (the demo's last stage).
    pub relight: (usize, u32),
    /// What it costs, as measured (docs/paper.md).
    pub wall_time: &'static str,
}

/// Test-only sizes: every stage and table end to end in about a minute, deciding nothing.
pub const TINY: Budget = Budget {
    name: "tiny",
    train_views: 24,
    test_views: 4,
    train_res: 32,
    test_res: 32,
    spp: 16,
    test_spp: 32,
    training: RunLength::epochs(2),
    deep_shading: RunLength::epochs(2),
    sh_spp: 16,
    timing_res: 64,
    temporal: (6, 32),
    relight: (4, 48),
    wall_time: "10 s on 2 cores on builtin:room (docs/paper.md)",
};

/// Within an hour on 2 cores on KITCHEN (36 minutes measured): 32 test views, enough to resolve
/// the paper's orderings where the designs differ by a few percent.
pub const SMALL: Budget = Budget {
    name: "small",
    train_views: 600,
    test_views: 32,
    train_res: 64,
    test_res: 64,
    spp: 64,
    test_spp: 512,
    training: RunLength::minutes(4.0),
    deep_shading: RunLength::minutes(4.0),
    sh_spp: 256,
    timing_res: 512,
    temporal: (12, 64),
    relight: (24, 128),
    wall_time: "36 minutes on 2 cores on KITCHEN (docs/paper.md)",
};

/// A night on a workstation's CPU.
pub const MEDIUM: Budget = Budget {
    name: "medium",
    train_views: 1500,
    test_views: 100,
    train_res: 128,
    test_res: 128,
    spp: 128,
    test_spp: 1024,
    training: RunLength::minutes(20.0),
    deep_shading: RunLength::minutes(20.0),
    sh_spp: 512,
    timing_res: 512,
    temporal: (24, 128),
    relight: (48, 256),
    wall_time: "about 5 hours on 2 cores on KITCHEN, projected from small's rates (docs/paper.md)",
};

/// The paper's sizes: 3000 views of 256², 200 test views of 400², 3200-spp references, 500
/// epochs at its constant learning rate. For a cluster and a GPU (docs/paper.md).
pub const PAPER: Budget = Budget {
    name: "paper",
    train_views: 3000,
    test_views: 200,
    train_res: 256,
    test_res: 400,
    spp: 3200,
    test_spp: 3200,
    training: RunLength {
        epochs: Some(500),
        minutes: None,
        lr_schedule: Some(LrSchedule::Paper),
    },
    deep_shading: RunLength {
        epochs: Some(500),
        minutes: None,
        lr_schedule: Some(LrSchedule::Paper),
    },
    sh_spp: 1024,
    timing_res: 512,
    temporal: (48, 256),
    relight: (96, 512),
    wall_time: "about 52 days on 2 cores on KITCHEN, projected: a cluster for the data and a GPU for training (docs/paper.md)",
};

/// The demo's sizes: 800 lightings at 32² rather than 200 at 64² (the same pixels and tracing
/// time): held-out lighting is what the networks fail at, and more lightings teach the encoder
/// more (docs/evaluation.md#what-the-demo-shows). For the same reason 48 test lightings at 64²
/// rather than 16 at 96²: the paper's designs differ by less than 16 lightings resolve.
pub const DEMO: Budget = Budget {
    name: "demo",
    train_views: 800,
    test_views: 48,
    train_res: 32,
    test_res: 64,
    spp: 64,
    test_spp: 1024,
    training: RunLength::minutes(2.0),
    deep_shading: RunLength::minutes(2.0),
    sh_spp: 256,
    timing_res: 512,
    temporal: (12, 64),
    relight: (48, 128),
    wall_time: "about 17 minutes on 2 cores (README)",
};

impl Budget {
    /// The budgets `nprt paper --budget` takes, smallest first.
    pub const CHOICES: [Budget; 4] = [TINY, SMALL, MEDIUM, PAPER];
}

impl FromStr for Budget {
    type Err = anyhow::Error;

    fn from_str(s: &str) -> Result<Budget> {
        match Budget::CHOICES.into_iter().find(|b| b.name == s) {
            Some(b) => Ok(b),
            None => bail!(
                "unknown budget '{s}': choose {}",
                Budget::CHOICES.map(|b| b.name).join(", ")
            ),
        }
    }
}

impl fmt::Display for Budget {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budgets_are_named_by_what_they_parse_from_and_grow() {
        for b in Budget::CHOICES {
            assert_eq!(b.name.parse::<Budget>().unwrap(), b);
        }
        assert!("huge"
            .parse::<Budget>()
            .unwrap_err()
            .to_string()
            .contains("tiny, small"));
        // Each budget traces more than the one before, and test references are rendered in
        // two halves (an even count).
        let samples = |b: &Budget| {
            b.train_views * u64::from(b.train_res.pow(2) * b.spp)
                + b.test_views * u64::from(b.test_res.pow(2) * b.test_spp)
        };
        for w in Budget::CHOICES.windows(2) {
            assert!(samples(&w[0]) < samples(&w[1]), "{} vs {}", w[0], w[1]);
        }
        for b in Budget::CHOICES.into_iter().chain([DEMO]) {
            assert_eq!(b.test_spp % 2, 0, "{b}");
        }
    }
}
