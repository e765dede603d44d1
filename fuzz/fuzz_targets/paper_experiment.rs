//! Any bytes as an `nprt paper` folder's experiment.json must be refused or read as a record
//! (a JSON object) to compare with the run's own: never a panic or a runaway on deep nesting.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(record) = nprt_paper::readback::experiment_record(data, Path::new("experiment.json"))
    {
        assert!(record.is_object());
    }
});
