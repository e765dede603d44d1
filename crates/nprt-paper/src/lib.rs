//! nprt-paper: the paper's experiments end to end. It owns the pipeline that runs one scene
//! through every stage (dataset, the four designs and Table 2's ablation, Deep Shading, the
//! evaluation against every baseline, a relit camera path) at a budget stated once, resuming
//! whatever a killed run left, and the report that sets the paper's Tables 1-6 beside its own
//! figures and judges the orderings it states. `nprt demo` and `nprt paper` are two presets of
//! it; `bake` is its shortest path, a scene to a model of the recommended recipe checked against
//! path tracing (`nprt bake`). It calls the stages' libraries and must not hold their logic:
//! tracing, training, metrics and baselines stay in nprt-data, nprt-net and nprt-eval.

pub mod bake;
pub mod budget;
mod claim;
mod experiment;
mod growth_report;
pub mod orderings;
mod paper_figures;
mod paper_report;
mod pipeline;
pub mod power_law;
pub mod published;
pub mod readback;
mod stage_log;
mod stages;

pub use budget::Budget;
pub use experiment::Experiment;
pub use paper_report::{report_tables, stage_table};
pub use pipeline::Outcome;
