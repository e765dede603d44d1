//! Any bytes as a model folder's model.json must be refused or describe a network every
//! command can use: its level gain within the range a calibration measures, its widths and
//! basis of a size the loader allows and this machine holds, its bounds finite; never a panic.
//! (model_folder fuzzes the config with its weights; this one reaches the fields alone.)
#![no_main]

use libfuzzer_sys::fuzz_target;
use nprt_net::model::folder::{read_model_file, CONFIG_FILE, LEVEL_GAIN_RANGE};
use nprt_net::network::encoder::MAX_INPUT_WIDTH;
use nprt_net::network::light_basis::MAX_LEARNED;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("nprt-fuzz-config-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(CONFIG_FILE), data).unwrap();
    let Ok(file) = read_model_file(&dir) else {
        return;
    };
    let config = &file.config;
    assert!(config.encoder_width <= MAX_INPUT_WIDTH && config.encoder_width % 64 == 0);
    if config.design.is_linear() {
        assert!(config.light_basis().size() <= MAX_LEARNED.max(256));
    }
    for g in file.output_gain() {
        assert!(LEVEL_GAIN_RANGE.contains(&g), "{g}");
    }
    assert!(file.bounds.iter().flatten().all(|v| v.is_finite()));
    assert!(!file.describe("16 spp").is_empty() && !config.label().is_empty());
    // Built where it fits libFuzzer's memory limit (a learned:1024 basis at width 1024 is 2 GB,
    // which the loader allows where the machine holds it).
    if config.floats_bound() < 64 << 20 {
        let net = config.build(&mut nprt_net::Init::new(0));
        assert!(net.total_params() as u128 <= config.floats_bound());
    }
});
