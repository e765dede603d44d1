//! Any bytes as an `nprt paper` folder's report/results.json must be refused (the evaluation is
//! then redone) or give the report's tables with no NaN or infinity in them. Input: a byte for
//! the test views the run expects (1 to 8; its top bit says the scene is KITCHEN), a byte for
//! its networks (0 to 5), then results.json.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

#[path = "paper_oracle.rs"]
mod paper_oracle;

fuzz_target!(|data: &[u8]| {
    let Some(([views, models], json)) = data.split_first_chunk::<2>() else {
        return;
    };
    let file = Path::new("results.json");
    let (views, models) = ((views & 7) as usize + 1, (models % 6) as usize);
    let Ok(e) = nprt_paper::readback::evaluation(json, file, views, models) else {
        return;
    };
    let md = nprt_paper::report_tables(&e, &[], data[0] & 128 != 0).unwrap();
    assert!(!paper_oracle::shows_non_finite(&md, json), "{md}");
});
