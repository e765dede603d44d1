//! Any bytes as an `nprt paper` folder's report/table2.json (Table 2's runs) must be refused
//! (they are then scored again) or give the report's tables with no NaN or infinity, beside the
//! evaluation they are read with. Input: a little-endian u32 length, that many bytes of
//! results.json (read for 2 test views and the paper's 4 designs), then table2.json.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

#[path = "paper_oracle.rs"]
mod paper_oracle;

fuzz_target!(|data: &[u8]| {
    let Some((results, table2)) = paper_oracle::split_pair(data) else {
        return;
    };
    let Ok(a) = nprt_paper::readback::ablation(table2, Path::new("table2.json")) else {
        return;
    };
    let Ok(e) = nprt_paper::readback::evaluation(results, Path::new("results.json"), 2, 4) else {
        return;
    };
    let md = nprt_paper::report_tables(&e, &a.rows, false).unwrap();
    assert!(!paper_oracle::shows_non_finite(&md, data), "{md}");
});
