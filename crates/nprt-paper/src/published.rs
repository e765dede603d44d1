//! The paper's own figures, as printed in its Tables 1 to 6 (transcribed in
//! ../shared/paper-tables.md), each with its table, scene and unit, for the report to set
//! beside nprt's. Per-design figures are in [`Design::PAPER`]'s order (the paper's); a design
//! beyond the paper has none.

use nprt_net::Design;

/// Where the figures below, and Table 1's (`Design::paper_params`), were read.
pub const SOURCE: &str = "the paper's Tables 1 to 6 as printed (Rainer et al., CGF 2022), \
     transcribed in ../shared/paper-tables.md";

/// The paper's scenes, in its tables' order (Tables 4 and 5 have all four).
pub const SCENES: [&str; 4] = ["ATELIER", "BEDROOM", "KITCHEN", "SANMIGUEL"];

/// Table 2's scenes (the first two of [`SCENES`]).
pub const TABLE2_SCENES: [&str; 2] = ["ATELIER", "BEDROOM"];

/// Table 2, per run (baseline (R), baseline (S), PRT-inspired (R), PRT-inspired (S): the order
/// of `orderings::ablation_configs`) and scene: the validation loss × 10³ and the RMSE × 10³.
/// The paper prints the RMSE as a fraction (0.058), not × 10³ as its loss.
pub const TABLE2: [[[f64; 2]; 2]; 4] = [
    [[19.0, 58.0], [6.6, 23.0]],
    [[24.4, 68.0], [31.2, 56.0]],
    [[17.8, 56.0], [6.3, 22.0]],
    [[16.0, 49.0], [6.2, 21.0]],
];

/// Table 3: the light encoder's milliseconds per 512² frame on an RTX 3090.
pub const ENCODER_MS: f64 = 0.34;

/// Table 3: each of the paper's designs' network, milliseconds per 512² frame on an RTX 3090
/// (upper bounds: background pixels included); None for a design beyond the paper.
pub fn network_ms(design: Design) -> Option<f64> {
    of_paper_design([9.73, 10.57, 10.60, 16.02], design)
}

/// Table 4: Falcor's G-buffer and path tracing at 5 spp, milliseconds per 512² frame on an
/// RTX 3090, per scene of [`SCENES`].
pub const GBUFFER_MS: [f64; 4] = [3.0, 3.0, 4.0, 8.0];
pub const PATH_TRACING_5SPP_MS: [f64; 4] = [19.0, 24.0, 27.0, 36.0];

/// Table 5, per scene of [`SCENES`] and design (the paper's four, in its order): the test
/// views' log-L1 loss × 10³ and RMSE × 10³.
pub const TABLE5: [[[f64; 2]; 4]; 4] = [
    [[18.95, 57.6], [15.96, 49.4], [14.70, 47.9], [14.66, 46.8]],
    [[6.64, 23.5], [6.17, 21.3], [6.02, 20.5], [5.50, 20.0]],
    [[3.15, 16.6], [2.79, 15.0], [2.69, 15.1], [2.65, 14.8]],
    [[4.05, 15.8], [3.73, 15.0], [3.54, 14.3], [3.51, 13.9]],
];

/// Table 5: `design`'s loss and RMSE × 10³ in scene `scene` of [`SCENES`] (None for a design
/// beyond the paper).
pub fn table5(scene: usize, design: Design) -> Option<[f64; 2]> {
    Some(TABLE5[scene][paper_index(design)?])
}

/// Table 6's rows, as the paper names them (its D/S last).
pub const TABLE6_METHODS: [&str; 8] = [
    "RTPT (5 spp)",
    "RTPT + denoise",
    "NRC",
    "NRC-CACHE",
    "Deep Shading",
    "PRT-9",
    "PRT-25",
    "Ours (D/S)",
];

/// Table 6, per scene (ATELIER, BEDROOM) and row of [`TABLE6_METHODS`]: L1, L2, dSSIM, MAPE
/// and MRSE × 10³, averaged over the frames of a camera path (PRT: one frame).
pub const TABLE6: [(&str, [[f64; 5]; 8]); 2] = [
    (
        "ATELIER",
        [
            [124.21, 71.20, 597.92, 328.70, 230.02],
            [293.65, 182.57, 686.87, 689.80, 453.46],
            [98.19, 34.29, 533.98, 268.22, 137.64],
            [68.75, 15.21, 245.93, 208.58, 72.22],
            [51.39, 15.75, 172.61, 175.06, 39.11],
            [64.86, 19.18, 147.93, 171.43, 72.53],
            [36.83, 11.41, 88.27, 81.74, 29.99],
            [30.23, 5.34, 63.95, 80.46, 22.02],
        ],
    ),
    (
        "BEDROOM",
        [
            [49.48, 13.22, 579.23, 683.72, 511.64],
            [151.18, 45.24, 519.14, 1889.00, 1526.00],
            [35.21, 11.17, 400.60, 442.90, 164.90],
            [26.21, 3.36, 237.2, 366.50, 77.44],
            [16.15, 3.91, 89.38, 219.37, 47.19],
            [14.72, 3.17, 84.97, 172.72, 47.64],
            [12.63, 7.71, 55.65, 117.85, 19.62],
            [9.89, 2.09, 36.95, 100.20, 21.76],
        ],
    ),
];

/// `design`'s figure of `figures`, given in [`Design::PAPER`]'s order (the paper's tables').
fn of_paper_design(figures: [f64; 4], design: Design) -> Option<f64> {
    Some(figures[paper_index(design)?])
}

/// Where `design` stands in the paper's tables (None for a design beyond the paper).
fn paper_index(design: Design) -> Option<usize> {
    Design::PAPER.iter().position(|&d| d == design)
}
