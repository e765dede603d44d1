//! nprt-eval: how good and how fast the trained models are. It owns the error metrics, the
//! paper's baselines (path tracing at 5 spp and at equal time, optionally denoised with Open
//! Image Denoise; per-pixel SH PRT with 9 and 25 coefficients; Deep Shading, a per-scene U-Net),
//! the error analysis, the timing tables and the Markdown/HTML report. It renders neural frames
//! through nprt-render and reference-style frames through nprt-trace; it must not write
//! datasets or train the Neural PRT designs (nprt-net does).
//!
//! ```
//! use glam::Vec3;
//! use nprt_eval::metrics::Metrics;
//!
//! // The paper's image errors of a prediction against its reference, on foreground pixels.
//! let reference = vec![Vec3::splat(0.5); 64];
//! let prediction = vec![Vec3::splat(0.6); 64];
//! let m = Metrics::compute(&prediction, &reference, &[1.0; 64], 8);
//! assert!((m.l1 - 0.1).abs() < 1e-6);
//! ```

pub mod claim;
mod error_analysis;
mod eval_options;
mod evaluate;
mod method;
pub mod metrics;
mod networks;
pub mod nrc;
mod oracles;
mod path_tracing;
mod report;
pub mod sh;
mod sh_prt;
mod shown_view;
mod stopwatch;
pub mod temporal;
mod test_bench;
mod timing;

pub use eval_options::EvalOptions;
pub use evaluate::{evaluate, score_networks, Evaluation};
pub use method::{Family, MethodResult, BINS};
pub use metrics::Metrics;
pub use networks::row_name;
pub use report::{
    auto_exposure, crop_image, markdown_to_html, mean_and_se, mean_and_se_text, plot_validation,
    table6, write_report, VALIDATION_PLOT,
};
pub use timing::Timing;
