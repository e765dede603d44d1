//! Any bytes as an `nprt paper` folder's stage-times.json must be refused or give a stage table
//! of plain durations: never a panic, a NaN, an infinity or a negative time.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

#[path = "paper_oracle.rs"]
mod paper_oracle;

fuzz_target!(|data: &[u8]| {
    let Ok(times) = nprt_paper::readback::stage_times(data, Path::new("stage-times.json")) else {
        return;
    };
    let md = nprt_paper::stage_table(&times).unwrap();
    assert!(!paper_oracle::shows_non_finite(&md, data), "{md}");
    // Each row's last cell is its duration (a stage's name is free text).
    for row in md.lines().filter(|l| l.ends_with(" |")) {
        let duration = row.trim_end_matches(" |").rsplit("| ").next().unwrap_or("");
        assert!(
            !duration.trim_start_matches("**").starts_with('-'),
            "a negative time: {row}"
        );
    }
});
