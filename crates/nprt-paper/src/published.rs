//! The paper's own figures that nprt holds, each with where it comes from. What nprt does not
//! hold is absent rather than guessed: the report says which columns stay empty.

use nprt_net::Design;

/// Where the figures below, and Table 1's (`Design::paper_params`), were read.
pub const TABLE_1_SOURCE: &str = "the paper's Table 1 (as ../shared/DESIGN.md summarises it)";
pub const TABLES_3_4_SOURCE: &str =
    "the paper's Tables 3 and 4, at 512² on an RTX 3090 (as ../shared/DESIGN.md summarises them)";
pub const TABLE_5_SOURCE: &str = "the paper's Table 5, its KITCHEN row, as docs/kitchen.md has \
     recorded it since 8b39f53 (not checked against the paper within this repository)";
/// What nprt lacks of the paper's figures.
pub const MISSING: &str = "Table 2's and Table 6's figures, Table 5's log-loss and its rows of \
     ATELIER, BEDROOM and SANMIGUEL are not transcribed in this repository, so those columns \
     stay empty rather than guessed";

/// Tables 3 and 4: the light encoder's milliseconds per 512² frame.
pub const ENCODER_MS: f64 = 0.34;

/// Tables 3 and 4: each of the paper's designs' network, milliseconds per 512² frame (None for
/// a design beyond the paper).
pub fn network_ms(design: Design) -> Option<f64> {
    of_paper_design([9.73, 10.57, 10.60, 16.02], design)
}

/// Tables 3 and 4: Falcor's path tracing at 5 spp, milliseconds per 512² frame (a range over
/// the paper's scenes).
pub const PATH_TRACING_5SPP_MS: (f64, f64) = (19.0, 36.0);

/// Table 5, KITCHEN: RMSE × 10³ per design (None for a design beyond the paper).
pub fn kitchen_rmse_e3(design: Design) -> Option<f64> {
    of_paper_design([16.6, 15.0, 15.1, 14.8], design)
}

/// `design`'s figure of `figures`, given in [`Design::PAPER`]'s order (the paper's tables').
fn of_paper_design(figures: [f64; 4], design: Design) -> Option<f64> {
    let index = Design::PAPER.iter().position(|&d| d == design)?;
    Some(figures[index])
}
