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
    assert!(!md.contains("| -"), "a negative time: {md}");
});
