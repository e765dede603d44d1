//! Any bytes as what a GPU visit's landing reads (bench/kitchen-visit.sh land: `nprt model
//! land`) must be refused or give rows of plain figures: the first byte chooses the run's
//! visits.csv (even) or the visit's checkpoint/state.json (odd), the rest is the file. Never a
//! panic, and no accepted row with a time, a loss or a date no visit writes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nprt_net::training::visits::{parse_visits, Visit};

fn plain(v: &Visit) {
    assert!(v.problem().is_none(), "{v:?}");
    assert!(v.gpu_minutes.is_finite() && v.gpu_minutes >= 0.0, "{v:?}");
    assert!(v.val_loss.is_finite() && v.val_loss >= 0.0, "{v:?}");
}

fuzz_target!(|data: &[u8]| {
    let Some((&kind, file)) = data.split_first() else {
        return;
    };
    if kind % 2 == 0 {
        if let Ok(rows) = parse_visits(file) {
            rows.iter().for_each(plain);
            assert!(rows.windows(2).all(|w| w[0].samples <= w[1].samples));
        }
        return;
    }
    let dir = std::env::temp_dir().join(format!("nprt-fuzz-visit-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("checkpoint")).unwrap();
    std::fs::write(dir.join("checkpoint/state.json"), file).unwrap();
    if let Ok(v) = Visit::of_model(&dir, "2026-11-29T12:00Z") {
        plain(&v);
    }
});
